#!/usr/bin/env bash
# Plume's growth against Blender's interpolated hair children on the same job, in one run: Sintel's
# head and 228 guides, 100,000 strands (Blender: 100,092 children, 439 per guide) of 32 points
# (Blender: 33, 2^5 + 1), two threads each; medians of repeated runs; then the ratio of the times
# and of the points per second.
#
#   bench/vs_blender.sh [RUNS]        (from the repository's root; default 7 runs)
#
# Needs a build with the benchmarks (cmake -S . -B build -DPLUME_BUILD_BENCH=ON && cmake --build
# build -j2 --target bench_sintel) and Blender 3.4 (Debian 12: apt-get install blender). Figures
# from a shared or busy machine move with its load: run it on a quiet one.
set -euo pipefail
cd "$(dirname "$0")/.."

runs=${1:-7}
bench=build/bench/bench_sintel
if [[ ! -x $bench ]]; then
  echo "vs_blender: $bench is missing: cmake -S . -B build -DPLUME_BUILD_BENCH=ON && cmake --build build -j2 --target bench_sintel" >&2
  exit 2
fi
if ! command -v blender >/dev/null 2>&1; then
  echo "vs_blender: blender is missing (Debian 12: apt-get install blender)" >&2
  exit 2
fi

echo "== Plume: $bench 100000 $runs"
plume_out=$("$bench" 100000 "$runs")
echo "$plume_out"
echo
echo "== Blender $(blender --version 2>/dev/null | head -1 | awk '{print $2}'): bench/blender_children.py"
blender_out=$(blender -b --factory-startup -t 2 --python bench/blender_children.py -- --runs "$runs" 2>&1 |
              grep -E '^(parents|children|evaluation|BLENDER_CHILDREN)')
echo "$blender_out"
echo

field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p"; }
blender_line=$(grep '^BLENDER_CHILDREN' <<<"$blender_out")
blender_s=$(field median_s <<<"$blender_line")
blender_rate=$(field points_per_s <<<"$blender_line")
blender_children=$(field children <<<"$blender_line")
blender_points=$(field points <<<"$blender_line")
printf '%-34s %12s %14s %26s\n' "one run, $(nproc) cores, 2 threads" "median s" "points/s" "time / Blender's children"
printf '%-34s %12.3f %14.3e %26s\n' "Blender children ($blender_children x $blender_points)" "$blender_s" "$blender_rate" "1"
while read -r line; do
  method=$(field method <<<"$line")
  seconds=$(field median_s <<<"$line")
  rate=$(field points_per_s <<<"$line")
  ratio=$(awk -v a="$seconds" -v b="$blender_s" 'BEGIN { printf "%.2fx", a / b }')
  printf '%-34s %12.3f %14.3e %26s\n' "Plume $method (100000 x 32)" "$seconds" "$rate" "$ratio"
done < <(grep '^PLUME_GROWTH' <<<"$plume_out")
