#!/usr/bin/env bash
# The installed package, as research code sees it (README, "Using rcm from
# your code"). After scripts/build.sh:
#   1. `cmake --install build --prefix P` into a fresh temporary prefix;
#   2. examples/consumer, configured with find_package(rcm 0.2) against P
#      alone, with every installed header compiled in one file, built and
#      run on the bundled matches: its n must equal `P/bin/rcm estimate`'s
#      to 1e-12;
#   3. a project that add_subdirectory()s this repository configures, with
#      rcm's tests and benchmarks off;
#   4. the Python package imported from P and its pytest suite run
#      (python/tests), when it was built;
#   5. the snippets of docs/api.md compiled and run (scripts/test_docs.py).
# Everything it makes lives under one temporary folder, removed on exit.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
build=${RCM_BUILD_DIR:-build}
work=$(mktemp -d "${TMPDIR:-/tmp}/rcm-install.XXXXXX")
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
python=/usr/bin/python3

echo "== install into a fresh prefix"
cmake --install "$build" --prefix "$prefix" >"$work/install.log"
for f in lib/cmake/rcm/rcmConfig.cmake lib/cmake/rcm/rcmConfigVersion.cmake \
         bin/rcm include/rcm/estimation/batch_refinement.h; do
  [[ -e $prefix/$f ]] || { echo "test_install: $f not installed" >&2; exit 1; }
done
soname=$(readelf -d "$prefix"/lib/librcm.so | sed -n 's/.*SONAME.*\[\(.*\)\]/\1/p')
[[ $soname == librcm.so.0.2 ]] || {
  echo "test_install: librcm.so has SONAME '$soname', expected librcm.so.0.2" >&2
  exit 1
}
# rcm::rcm stands without the libraries on top of it: the simulator, the
# pictures and the bags are libraries of their own (scripts/check_layers.py).
for library in rcm_sim rcm_viz rcm_rosbag rcm_calib; do
  if readelf -d "$prefix"/lib/librcm.so | grep -q "NEEDED.*lib$library"; then
    echo "test_install: librcm.so needs lib$library" >&2
    exit 1
  fi
done
echo "installed $(find "$prefix" -type f | wc -l) files; SONAME $soname"

echo "== examples/consumer against the install tree"
cmake -S examples/consumer -B "$work/consumer" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DRCM_CONSUMER_CHECK_HEADERS=ON \
  >"$work/consumer-configure.log" || { cat "$work/consumer-configure.log"; exit 1; }
cmake --build "$work/consumer" -j2 >"$work/consumer-build.log" ||
  { cat "$work/consumer-build.log"; exit 1; }
calib=examples/data/alphasense_front_rectified.yaml
matches=examples/data/demo_matches.csv
"$work/consumer/consumer" "$calib" "$matches" | tee "$work/consumer.out"
# The installed executable must run from the prefix alone (its RPATH).
env -u LD_LIBRARY_PATH "$prefix/bin/rcm" estimate --calib "$calib" \
  --matches "$matches" --json >"$work/estimate.json"
"$python" - "$work/consumer.out" "$work/estimate.json" <<'PY'
import json, sys
consumer = dict(line.split(" = ", 1) for line in open(sys.argv[1]).read().splitlines())
n_consumer = float(consumer["n"])
n_cli = json.load(open(sys.argv[2]))["n"]
if abs(n_consumer - n_cli) > 1e-12:
    sys.exit(f"test_install: consumer n {n_consumer!r} != rcm estimate n {n_cli!r}")
print(f"consumer n equals rcm estimate's: |{n_consumer!r} - {n_cli!r}| <= 1e-12")
PY

echo "== add_subdirectory(rcm) from another project"
mkdir -p "$work/parent"
cat >"$work/parent/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.16)
project(parent LANGUAGES CXX)
add_subdirectory("$root" rcm)
add_executable(app app.cc)
target_link_libraries(app PRIVATE rcm::rcm)
CMAKE
echo 'int main() { return 0; }' >"$work/parent/app.cc"
cmake -S "$work/parent" -B "$work/parent-build" -DRCM_BUILD_PYTHON=OFF \
  >"$work/parent.log" || { cat "$work/parent.log"; exit 1; }
targets=$(cmake --build "$work/parent-build" --target help)
for t in rcm rcm_calib app; do
  grep -qw "$t" <<<"$targets" ||
    { echo "test_install: add_subdirectory: no target $t" >&2; exit 1; }
done
if grep -Eq 'estimation_tests|estimation_benchmark' <<<"$targets"; then
  echo "test_install: add_subdirectory built rcm's tests or benchmarks" >&2
  exit 1
fi
echo "configures: rcm, rcm_calib and app defined, rcm's tests and benchmarks off"

python_dir=$(find "$prefix" -path '*/rcm/__init__.py' -printf '%h\n' -quit)
if [[ -n $python_dir ]]; then
  echo "== the Python package from the prefix"
  export PYTHONPATH=$(dirname "$python_dir")
  export RCM_EXECUTABLE=$prefix/bin/rcm
  # The C++ refinement printed to 17 digits, for the exact comparison.
  if [[ -x $build/bin/rcm_refine_timing ]]; then
    RCM_REFINE_TIMING=$(cd "$build/bin" && pwd)/rcm_refine_timing
    export RCM_REFINE_TIMING
  fi
  (cd "$work" && "$python" -c 'import rcm; print("rcm", rcm.__version__, "from", rcm.__file__)')
  "$python" -m pytest -q -p no:cacheprovider python/tests
else
  echo "== the Python package was not built (RCM_BUILD_PYTHON, pybind11-dev): skipped"
fi

if [[ -f scripts/test_docs.py ]]; then
  echo "== docs/api.md snippets"
  RCM_PREFIX=$prefix "$python" scripts/test_docs.py
fi
echo "test_install: all passed"
