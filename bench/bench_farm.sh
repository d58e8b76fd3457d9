#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# What the farm path costs: the same work — the paper box split into 2 seeds — as 2 Slurm array tasks of one
# CPU each plus the combine job (chromatrace farm render --wait, on a single-node Slurm on localhost brought up
# by tests/farm/local_slurm.sh; needs root and slurm-wlm, munge) against one local 2-thread run
# (chromatrace render --seeds 2 --threads 2). Both give the same bytes (checked). Also the farm path with
# almost no work (8x8 pixels, 2 paths), which is its fixed cost. Best of N runs each (default 3).
#   bench/bench_farm.sh [BUILD_DIR] [RESOLUTION] [SPP] [N]
set -euo pipefail
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
build_dir="${1:-$source_dir/build}"
resolution="${2:-128x128}"
spp="${3:-256}"
runs="${4:-3}"
exe="$build_dir/cli/chromatrace"
scene="$source_dir/scenes/paper/box.json"
work="$(mktemp -d)"
trap '"$source_dir/tests/farm/local_slurm.sh" stop "$work/slurm"; rm -rf "$work"' EXIT

eval "$("$source_dir/tests/farm/local_slurm.sh" start "$work/slurm")"
export SLURM_CONF

seconds() { local start end; start=$(date +%s.%N); "$@" >/dev/null 2>&1; end=$(date +%s.%N); awk "BEGIN{print $end - $start}"; }
best() {
  local best=""
  for _ in $(seq "$runs"); do
    s=$(seconds "$@")
    if [ -z "$best" ] || awk "BEGIN{exit !($s < $best)}"; then best=$s; fi
  done
  echo "$best"
}

local_s=$(best "$exe" render "$scene" --resolution "$resolution" --spp "$spp" --seeds 2 --threads 2 -q -o "$work/local.exr")
farm_s=$(best "$exe" farm render "$scene" --resolution "$resolution" --spp "$spp" --seeds 2 --cpus-per-task 1 -q \
  -o "$work/farm" --wait)
cmp -s "$work/local.exr" "$work/farm/render.exr" || { echo "bench_farm.sh: the farm's render differs from the local one" >&2; exit 1; }
empty_local_s=$(best "$exe" render "$scene" --resolution 8x8 --spp 2 --seeds 2 --threads 2 -q -o "$work/empty.exr")
empty_farm_s=$(best "$exe" farm render "$scene" --resolution 8x8 --spp 2 --seeds 2 --cpus-per-task 1 -q -o "$work/empty" --wait)

printf 'paper box %s, %s paths per pixel in 2 seeds (best of %s)\n' "$resolution" "$spp" "$runs"
printf '%-44s %7.2f s\n' "local: render --seeds 2 --threads 2" "$local_s"
printf '%-44s %7.2f s   (%.2f x local, +%.2f s)\n' "farm: 2 tasks x 1 CPU, then combine" "$farm_s" \
  "$(awk "BEGIN{print $farm_s / $local_s}")" "$(awk "BEGIN{print $farm_s - $local_s}")"
printf '%-44s %7.2f s\n' "local, 8x8 and 2 paths" "$empty_local_s"
printf '%-44s %7.2f s   (the farm path'"'"'s fixed cost)\n' "farm, 8x8 and 2 paths" "$empty_farm_s"
