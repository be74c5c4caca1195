#!/usr/bin/env bash
# Installs the Debian packages rcm needs (when missing), then configures and
# builds everything in Release into build/ with two jobs. Extra arguments go
# to the CMake configure step, e.g. -DRCM_BUILD_BENCHMARKS=OFF.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
# Debian's interpreter, which has python3-numpy (a pyenv or venv python3
# earlier on PATH may not): the Python package is built for it.
# Ninja (ninja-build) for a new build folder: it compiles a target's
# objects while the libraries they link are still being built, which
# make's per-target steps do not. An existing folder keeps its generator.
generator=()
if [[ ! -f build/CMakeCache.txt ]] && command -v ninja >/dev/null; then
  generator=(-G Ninja)
fi
cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DPython3_EXECUTABLE=/usr/bin/python3 "$@"
cmake --build build -j2
