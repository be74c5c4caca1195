#!/usr/bin/env bash
# Builds every test, the rcm executable and the fuzz targets with clang
# under AddressSanitizer and UndefinedBehaviorSanitizer into build-sanitize/,
# runs the whole test suite there (any sanitizer report fails its test),
# then runs each fuzz target briefly from its seed corpus.
#
#   scripts/test_sanitizers.sh [FUZZ_SECONDS]   (default 5 per target)
#
# scripts/fuzz.sh 600 is the long fuzzing run (docs/testing.md, "Sanitizers,
# fuzzing and bad input").
set -euo pipefail
cd "$(dirname "$0")/.."
fuzz_seconds=${1:-5}
# Processes per test suite (scripts/test.sh sets it for both passes):
# enough that the two jobs stay busy to the end (the largest suite,
# cli_tests, is ~40 % of the pass).
shards=${RCM_TEST_SHARDS:-6}
./scripts/setup.sh
generator=()  # Ninja for a new build folder, as scripts/build.sh
if [[ ! -f build-sanitize/CMakeCache.txt ]] && command -v ninja >/dev/null; then
  generator=(-G Ninja)
fi
# The ROS1 node is left out: it is a thin adapter over rcm::LivePipeline,
# whose tests run here, and ROS's own headers are not ours to instrument.
# The libraries and the executable compile in unity batches
# (RCM_UNITY_BUILD, CMakeLists.txt: 485 s of CPU instead of about 890 s);
# the Release build compiles each file on its own.
cmake -S . -B build-sanitize "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_CXX_FLAGS=-gline-tables-only \
  -DRCM_SANITIZE=address,undefined -DRCM_BUILD_FUZZERS=ON -DRCM_UNITY_BUILD=ON \
  -DRCM_BUILD_BENCHMARKS=OFF -DBUILD_SHARED_LIBS=OFF -DRCM_BUILD_PYTHON=OFF \
  -DRCM_INSTALL=OFF -DRCM_WITH_ROS_NODE=OFF -DRCM_TEST_SHARDS=$shards
cmake --build build-sanitize -j2

# Reports abort the process (no recovery), with a symbolized stack.
# intercept_tls_get_addr=0: up to LLVM 16 the runtime's __tls_get_addr
# interceptor takes a dynamic TLS block that happens to start 16 bytes into
# a page for glibc 2.19's header and reads the two words before it as the
# block's range; LeakSanitizer's tracer then dies at exit ("Tracer caught
# signal 11", exit 1, no leak reported). The bag test (the TLS of Debian's
# ROS libraries) met it in 2 of 3 runs on one machine and in CI; whether a
# block lands there depends on the heap's layout, so it did not reproduce
# in 18 runs on another. The flag follows from that mechanism (fixed
# upstream in LLVM 17), not from a run that showed the crash gone. Without
# the interceptor the leak check still scans every thread's stack and
# static TLS.
export ASAN_OPTIONS=detect_leaks=1:strict_string_checks=1:intercept_tls_get_addr=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
if [[ -x /usr/lib/llvm-14/bin/llvm-symbolizer ]]; then
  export ASAN_SYMBOLIZER_PATH=/usr/lib/llvm-14/bin/llvm-symbolizer
fi
# The tests of the Release pass only are left out (scripts/test_passes.sh).
# shellcheck source=scripts/test_passes.sh
source scripts/test_passes.sh
# Each test suite runs as RCM_TEST_SHARDS processes (tests/CMakeLists.txt),
# the Release pass's tests filtered out by gtest itself.
tests=$(list_tests build-sanitize)
check_test_passes "$tests"
total=$(grep -c . <<<"$tests")
GTEST_FILTER="-$(join_patterns "${release_only[@]}")"
export GTEST_FILTER
kept=$(grep -c . < <(while read -r name; do
  matches_any "$name" "${release_only[@]}" || echo "$name"
done <<<"$tests"))
echo "test_sanitizers: $kept of $total tests," \
  "each suite in $shards processes (the Release pass runs the rest)"
ctest --test-dir build-sanitize --output-on-failure -j2
# A fixed seed: CI replays the same draw (scripts/fuzz.sh); the seed
# corpus holds every earlier finding.
RCM_FUZZ_SEED=1 RCM_FUZZ_BUILD_DIR=build-sanitize ./scripts/fuzz.sh "$fuzz_seconds"
