#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Start-up cost: wall time and peak memory (max RSS, from /usr/bin/time) of `chromatrace --help` and of
# `chromatrace check-scene` on the minimal scene (both run by the front executable), against /bin/true (the cost
# of starting any process) and `oiiotool --help` (a tool built on the same image libraries); and of
# `chromatrace render --help`, which the front hands to the full program (what every other command pays before
# its work). The best of N runs of each (default 10), and the mean of N more. The shared libraries loaded, from
# the loader's report (LD_DEBUG=files: each library it maps, once per executable started).
#   bench/bench_startup.sh [BUILD_DIR] [N]
set -euo pipefail
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
build_dir="${1:-$source_dir/build}"
runs="${2:-10}"
exe="$build_dir/cli/chromatrace"
scene="$source_dir/tests/data/scenes/minimal.json"
record="$(mktemp)"
trap 'rm -f "$record"' EXIT

measure() {
  local label="$1"
  shift
  local best_s="" best_kb="" start end
  # The mean wall time of N runs, timed around them (/usr/bin/time's own figure has a resolution of 10 ms).
  start=$(date +%s%N)
  for _ in $(seq "$runs"); do "$@" >/dev/null 2>&1 || true; done
  end=$(date +%s%N)
  for _ in $(seq "$runs"); do
    /usr/bin/time -o "$record" -f "%e %M" "$@" >/dev/null 2>&1 || true
    read -r s kb < <(tail -n 1 "$record")  # after "Command exited with non-zero status N", if any
    if [ -z "$best_s" ] || awk "BEGIN{exit !($s < $best_s)}"; then best_s="$s"; fi
    if [ -z "$best_kb" ] || [ "$kb" -lt "$best_kb" ]; then best_kb="$kb"; fi
  done
  printf '%-34s %6s s (mean %7.1f ms) %8.1f MB\n' "$label" "$best_s" "$(awk "BEGIN{print ($end - $start) / $runs / 1e6}")" \
    "$(awk "BEGIN{print $best_kb / 1024}")"
}

measure "/bin/true" /bin/true
measure "oiiotool --help" oiiotool --help
measure "chromatrace --help" "$exe" --help
measure "chromatrace check-scene minimal" "$exe" check-scene "$scene"
measure "chromatrace render --help" "$exe" render --help
loaded() { LD_DEBUG=files "$@" 2>&1 >/dev/null | grep -c "generating link map" || true; }
echo "shared libraries loaded: --help $(loaded "$exe" --help), check-scene $(loaded "$exe" check-scene "$scene")," \
  "render --help $(loaded "$exe" render --help)"
