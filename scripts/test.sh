#!/usr/bin/env bash
# Installs what is missing, builds, checks that the libraries' includes
# point down their layers (scripts/check_layers.py) and that
# docs/layout.md is true to the tree (scripts/check_layout.py), and runs
# every test (ctest, two jobs): the Release build (build/) and its
# statistical and accuracy tests; the installed package
# (scripts/test_install.sh: a consumer project, the Python package and its
# pytest suite, the docs' snippets); then the suite built with clang under
# AddressSanitizer and UndefinedBehaviorSanitizer, every test the Release
# pass did not run (scripts/test_passes.sh says which pass runs what),
# followed by a short run of each fuzz target (scripts/test_sanitizers.sh,
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
# The libraries' includes point down their layers, and docs/layout.md is
# true to the tree (a second each; after the build, whose setup.sh
# installs Debian's python3).
step /usr/bin/python3 scripts/check_layers.py
step /usr/bin/python3 scripts/check_layout.py
# The Release pass runs the tests whose statistics or accuracy only it
# checks (release_only, budgeted: scripts/test_passes.sh) and the node's
# test; every other test runs once, in the sanitizer pass, which catches
# more with the same checks.
# shellcheck source=scripts/test_passes.sh
source scripts/test_passes.sh
check_test_passes "$(list_tests build)"
# The node's test (tests/ros/node_test.sh) plays its bags in real time for
# ~2 minutes on a tenth of a core: it runs beside ctest's two jobs instead
# of holding one of them, and its output follows theirs.
release_ctest() {
  local node_log=build/Testing/ros_node_test.log status=0 node_status=0
  mkdir -p build/Testing
  ctest --test-dir build -R '^RosNode[.]' --output-on-failure \
    >"$node_log" 2>&1 &
  local node=$!
  GTEST_FILTER="$(join_patterns "${release_only[@]}" "${budgeted[@]}")" \
    ctest --test-dir build --output-on-failure -j2 -E '^RosNode[.]' ||
    status=$?
  wait "$node" || node_status=$?
  cat "$node_log"
  return $((status != 0 || node_status != 0))
}
step release_ctest
step ./scripts/test_install.sh
step ./scripts/test_sanitizers.sh
