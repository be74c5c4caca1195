#!/usr/bin/env bash
# Installs the Debian bookworm packages rcm builds against, when they are
# missing. Safe to run repeatedly: it only calls apt-get when something is
# absent. Must run as root (or with sudo available) on a machine that lacks
# a package.
set -euo pipefail

# Why each package is here: see README.md, section "Dependencies".
packages=(
  build-essential cmake pkg-config
  ninja-build          # the build tool scripts/build.sh uses (make works too)
  libeigen3-dev        # linear algebra, fixed-size math in the model
  libceres-dev         # nonlinear least squares, ceres::Jet autodiff
  libgflags-dev        # command-line flags of the rcm executable
  libgoogle-glog-dev   # CHECK macros for programmer errors
  libyaml-cpp-dev      # Kalibr camchain / ROS camera_info YAML
  nlohmann-json3-dev   # --json output
  libopencv-dev        # images: remap, drawing plots, SIFT, other image formats
  libpng-dev libjpeg-dev zlib1g-dev  # PNG/JPEG I/O and their silent integrity checks
  libopencv-contrib-dev  # aruco: AprilTag 36h11 and ChArUco targets
  opencv-doc           # the real stereo chessboard images a calibration test uses
  libgtest-dev libgmock-dev  # tests
  libbenchmark-dev     # benchmarks
  librosbag-storage-dev libsensor-msgs-dev  # ROS1 bags: rcm estimate/undistort --bag
  pluginlib-dev libclass-loader-dev librcpputils-dev librcutils-dev \
    libament-index-cpp-dev  # ROS 2 headers that rosbag's headers include
  clang-14 libclang-rt-14-dev  # sanitizer build and libFuzzer (test_sanitizers.sh)
  llvm-14              # llvm-symbolizer: source lines in sanitizer reports
  pybind11-dev python3-dev python3-numpy  # the Python package (python/)
  python3-pytest       # its tests
  python3-opencv       # cv2.remap with rcm's maps, in the Python tests and docs
  mrcal                # mrcal-calibrate-cameras: the peer the air calibration is tested against
  # The ROS1 node rcm_ros_node (ros/): the client library, image transport,
  # OpenCV bridge, stamp pairing, diagnostics, its service types and the
  # generators of its own message and service (gencpp, genpy)
  libroscpp-dev libimage-transport-dev libcv-bridge-dev libmessage-filters-dev \
    libdiagnostic-updater-dev libstd-srvs-dev ros-std-msgs ros-std-srvs \
    python3-gencpp python3-genpy
  # ... and its test (tests/ros/node_test.sh): roscore, rostopic, rosservice,
  # rosbag record/play and their Python messages; Debian's stereo_image_proc
  # (its node, nodelet plugin and the nodelet package it loads) on the
  # node's rectified output
  ros-core python3-sensor-msgs python3-std-srvs python3-diagnostic-msgs \
    python3-stereo-msgs ros-stereo-image-proc libstereo-image-proc-dev \
    libnodeletlib-tools
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  exit 0
fi

echo "rcm setup: installing ${missing[*]}" >&2
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null; then
    sudo_cmd=(sudo)
  else
    echo "rcm setup: missing packages (${missing[*]}) and not root; install them or rerun as root" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
