#!/usr/bin/env bash
# Builds every test, the rcm executable and the fuzz targets with clang
# under AddressSanitizer and UndefinedBehaviorSanitizer into build-sanitize/,
# runs the whole test suite there (any sanitizer report fails its test),
# then runs each fuzz target briefly from its seed corpus.
#
#   scripts/test_sanitizers.sh [FUZZ_SECONDS]   (default 20 per target)
#
# scripts/fuzz.sh 600 is the long fuzzing run (docs/testing.md, "Sanitizers,
# fuzzing and bad input").
set -euo pipefail
cd "$(dirname "$0")/.."
fuzz_seconds=${1:-20}
./scripts/setup.sh
cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_CXX_FLAGS=-gline-tables-only \
  -DRCM_SANITIZE=address,undefined -DRCM_BUILD_FUZZERS=ON \
  -DRCM_BUILD_BENCHMARKS=OFF -DBUILD_SHARED_LIBS=OFF -DRCM_BUILD_PYTHON=OFF \
  -DRCM_INSTALL=OFF
cmake --build build-sanitize -j2

# Reports abort the process (no recovery), with a symbolized stack.
export ASAN_OPTIONS=detect_leaks=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
if [[ -x /usr/lib/llvm-14/bin/llvm-symbolizer ]]; then
  export ASAN_SYMBOLIZER_PATH=/usr/lib/llvm-14/bin/llvm-symbolizer
fi
ctest --test-dir build-sanitize --output-on-failure -j2
RCM_FUZZ_BUILD_DIR=build-sanitize ./scripts/fuzz.sh "$fuzz_seconds"
