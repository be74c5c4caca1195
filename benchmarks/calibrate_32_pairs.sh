#!/usr/bin/env bash
# Times `rcm calibrate` (default settings: detection, bundle adjustment,
# 10-fold leave-out, report) on 32 rendered 640x480 pairs of a 9x6 board
# with 25 mm squares at 0.3-0.7 m, in air (rcm simulate --n 1, the
# narrow-field rig). The issue's target: under 10 s on 2 cores.
#
#   benchmarks/calibrate_32_pairs.sh [BUILD_DIR]   (default build)
set -euo pipefail
cd "$(dirname "$0")/.."
rcm=${1:-build}/bin/rcm
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$rcm" simulate --out "$work/air" --rig narrow --n 1.0 --frames 32 \
  --frame-rate 1 --board chessboard --cols 9 --rows 6 --square 0.025 \
  --board-distance 0.3,0.7 --matches-per-frame 10 >/dev/null
start=$(date +%s.%N)
"$rcm" calibrate --left "$work/air/left" --right "$work/air/right" \
  --board chessboard --cols 9 --rows 6 --square 0.025 --out "$work/out" \
  | grep -E "views used|rms"
end=$(date +%s.%N)
awk -v a="$start" -v b="$end" 'BEGIN { printf "rcm calibrate, 32 pairs: %.1f s\n", b - a }'
