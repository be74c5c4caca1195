#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (ctest, two jobs):
# the Release build (build/); the installed package (scripts/test_install.sh:
# a consumer project, the Python package and its pytest suite, the docs'
# snippets); then the same suite built with clang
# under AddressSanitizer and UndefinedBehaviorSanitizer, followed by a
# short run of each fuzz target (scripts/test_sanitizers.sh,
# build-sanitize/).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
ctest --test-dir build --output-on-failure -j2
./scripts/test_install.sh
./scripts/test_sanitizers.sh
