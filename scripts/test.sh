#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (ctest, two jobs):
# the Release build (build/); the installed package (scripts/test_install.sh:
# a consumer project, the Python package and its pytest suite, the docs'
# snippets); then the same suite built with clang
# under AddressSanitizer and UndefinedBehaviorSanitizer, followed by a
# short run of each fuzz target (scripts/test_sanitizers.sh,
# build-sanitize/). Each step's wall time is printed when it ends (CI must
# stay under 40 minutes on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
step() {
  local begin=$SECONDS
  "$@"
  echo "test.sh: $* took $((SECONDS - begin)) s ($((SECONDS - start)) s in all)"
}
# Each test suite as 6 ctest entries, its gtest shards, in both passes
# (tests/CMakeLists.txt, RCM_TEST_SHARDS; test_sanitizers.sh reads it from
# here): a test binary's start is longer than most tests. For one ctest
# entry per test (ctest -R NAME), configure build/ with -DRCM_TEST_SHARDS=0.
export RCM_TEST_SHARDS=6
step ./scripts/build.sh -DRCM_TEST_SHARDS="$RCM_TEST_SHARDS"
step ctest --test-dir build --output-on-failure -j2
step ./scripts/test_install.sh
step ./scripts/test_sanitizers.sh
