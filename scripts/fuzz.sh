#!/usr/bin/env bash
# Runs the libFuzzer targets of an RCM_BUILD_FUZZERS build, two at a time.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]
#
# SECONDS per target (default 600), TARGET names like fuzz_camera_model
# (default: every fuzz_* program in the build). The build directory is
# $RCM_FUZZ_BUILD_DIR (default build-sanitize, which scripts/
# test_sanitizers.sh makes). Each target starts from its seed corpus in
# fuzz/corpus/ (read only; new inputs go to a temporary folder) with its
# dictionary, when it has one. RCM_FUZZ_SEED, when set, is libFuzzer's
# -seed (CI's short run sets it: the same inputs in the same order on every
# run, so that a red CI is a change's, not a draw's; the long run leaves it
# unset, a new draw each time). A finding (crash, sanitizer report, violated
# property, leak, timeout) leaves the reproducer in fuzz-findings/ and makes
# the script exit 1; otherwise it prints each target's executions.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
shift || true
build_dir=${RCM_FUZZ_BUILD_DIR:-build-sanitize}
if (($# > 0)); then
  targets=("$@")
else
  mapfile -t targets < <(find "$build_dir/bin" -maxdepth 1 -name 'fuzz_*' \
                           -type f -executable -printf '%f\n' | sort)
fi
if ((${#targets[@]} == 0)); then
  echo "rcm fuzz: no fuzz_* programs in $build_dir/bin (run scripts/test_sanitizers.sh first)" >&2
  exit 1
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p fuzz-findings

run_one() {
  local target=$1 seconds=$2 build_dir=$3 work=$4
  local name=${target#fuzz_}
  local args=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048
              -print_final_stats=1 -artifact_prefix="fuzz-findings/$target-")
  [[ -f fuzz/$name.dict ]] && args+=(-dict="fuzz/$name.dict")
  [[ -n ${RCM_FUZZ_SEED:-} ]] && args+=(-seed="$RCM_FUZZ_SEED")
  mkdir -p "$work/$name"
  local seeds=()
  [[ -d fuzz/corpus/$name ]] && seeds+=("fuzz/corpus/$name")
  if "$build_dir/bin/$target" "${args[@]}" "$work/$name" "${seeds[@]}" \
       >"$work/$target.log" 2>&1; then
    local runs
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' \
             "$work/$target.log" | grep -o '[0-9]*$')
    printf '%-26s %10s executions in %s s, no finding\n' "$target" "$runs" \
      "$seconds"
  else
    echo "$target: FINDING (log below; reproducer in fuzz-findings/)"
    tail -n 60 "$work/$target.log"
    return 1
  fi
}
export -f run_one
printf '%s\n' "${targets[@]}" |
  xargs -P 2 -I{} bash -c 'run_one "$@"' _ {} "$seconds" "$build_dir" "$work"
