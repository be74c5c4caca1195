#!/usr/bin/env bash
# rcm_ros_node against the real ROS1 middleware: a private roscore on a
# loopback port of its own, the node, and `rosbag play` of a simulated
# air -> water -> air sequence (rcm simulate, written by write_stereo_bag.py).
# Checks: a bad ~calib is one line and exit 1; every played pair gives one
# ~refractive_index message whose named fields rostopic echo shows; both
# medium switches are flagged within 3 pairs of the truth's; n in each
# medium after its switch within 5e-3 of the truth. Everything it started
# is stopped on exit, also when a check fails, and the whole run is bounded
# by `timeout` in CMake (ctest's TIMEOUT).
#
# usage: node_test.sh BUILD_DIR PORT
set -euo pipefail
build=$1
port=$2
rcm=$build/bin/rcm
node=$build/bin/rcm_ros_node
work=$(mktemp -d /tmp/rcm_node_test.XXXXXX)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  for _ in $(seq 1 30); do
    alive=0
    for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
    ((alive)) || break
    sleep 0.1
  done
  for pid in "${pids[@]}"; do kill -9 "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "node_test: FAILED: $*" >&2; exit 1; }

export ROS_MASTER_URI=http://127.0.0.1:$port ROS_HOSTNAME=127.0.0.1
export ROS_HOME=$work/ros_home ROS_LOG_DIR=$work/ros_log
export ROS_PACKAGE_PATH=$build/ros PYTHONPATH=$build/ros/python
python=/usr/bin/python3

# 6 pairs in air, 10 in water (n = 1.333), 6 in air.
"$rcm" simulate --out "$work/sim" --media air:6,water:10,air:6 >/dev/null
"$python" "$(dirname "$0")/write_stereo_bag.py" "$work/sim" "$work/sim.bag" \
  --rate 4 >/dev/null

roscore -p "$port" >"$work/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 1 50); do
  rostopic list >/dev/null 2>&1 && break
  sleep 0.2
done
rostopic list >/dev/null 2>&1 || fail "roscore did not start on port $port"

# A bad ~calib: one line, exit 1.
set +e
out=$("$node" __name:=bad _calib:="$work/missing.yaml" 2>&1)
rc=$?
set -e
[[ $rc -eq 1 ]] || fail "a missing ~calib exited $rc, not 1"
[[ $(printf '%s\n' "$out" | grep -c .) -eq 1 ]] || fail "a missing ~calib printed more than one line: $out"
echo "bad ~calib: $out"

"$node" __name:=rcm __ns:=/stereo _calib:="$work/sim/camchain.yaml" \
  >"$work/node.log" 2>&1 &
pids+=($!)
rostopic echo -p /stereo/rcm/refractive_index >"$work/index.csv" 2>&1 &
pids+=($!)
# The node is up when its topic is advertised.
for _ in $(seq 1 50); do
  rostopic list 2>/dev/null | grep -q /stereo/rcm/refractive_index && break
  sleep 0.2
done
sleep 1
rosbag play -q "$work/sim.bag" >/dev/null 2>&1 || fail "rosbag play failed"
sleep 2

"$python" - "$work/index.csv" <<'PY' || { cat "$work/node.log" >&2; fail "see above"; }
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
truth = [1.0] * 6 + [1.333] * 10 + [1.0] * 6
stamps = [round(1000.0 + k / 4.0, 3) for k in range(len(truth))]
by_stamp = {round(int(r["field.header.stamp"]) * 1e-9, 3): r for r in rows}
print("node_test: %d messages for %d pairs" % (len(rows), len(truth)))
missing = [s for s in stamps if s not in by_stamp]
# rostopic echo may miss the first message while it connects.
if len(missing) > 1 or (missing and missing[0] != stamps[0]):
    sys.exit("pairs without a message: %s" % missing)
switches = [k for k, s in enumerate(stamps)
            if s in by_stamp and by_stamp[s]["field.medium_switch"] in ("1", "True")]
print("node_test: switches flagged at pairs %s (truth 6, 16)" % switches)
if len(switches) != 2 or not (6 <= switches[0] <= 8) or not (16 <= switches[1] <= 18):
    sys.exit("switches %s, not within 3 pairs of 6 and 16" % switches)
worst = 0.0
for k, s in enumerate(stamps):
    r = by_stamp.get(s)
    # Between a true switch and the pair that flags it the window mixes
    # the media.
    if r is None or 6 <= k < switches[0] or 16 <= k < switches[1]:
        continue
    if r["field.valid"] not in ("1", "True"):
        sys.exit("pair %d: no estimate: %s" % (k, r["field.status"]))
    n = float(r["field.n"])
    worst = max(worst, abs(n - truth[k]))
    print("node_test: pair %2d n %.5f +- %.5f (truth %.3f)" % (k, n, float(r["field.sigma_n"]), truth[k]))
if worst > 5e-3:
    sys.exit("n off by %.4f, more than 5e-3" % worst)
print("node_test: n within %.4f of the truth" % worst)
PY
echo "node_test: passed"
