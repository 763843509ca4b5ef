#!/usr/bin/env bash
# Runs every reader's libFuzzer target, one after the other:
#   tests/fuzz/run.sh [SECONDS] [RUNS]
# each for SECONDS (default 60), or until it has run RUNS inputs when RUNS is given and comes
# first (tests/fuzz/run.sh 7200 1000000: a million inputs per target). Builds build-fuzz with
# clang (Debian's clang and libclang-rt-dev, installed when missing), keeps each target's corpus in
# build-fuzz/corpus/<target> from run to run, seeded from the files of tests/data, and prints a
# table of inputs run and findings. A finding (a crash, a sanitizer report, an exception other
# than InputError, an invalid result, a timeout, memory beyond 2 GB) is saved as
# build-fuzz/findings/<target>-<kind>-<hash>; the script then exits with 1. Replay one with
# build-fuzz/tests/fuzz/<target> <file>.
set -euo pipefail
cd "$(dirname "$0")/../.."

seconds=${1:-60}
runs=${2:-}
if ! [[ "$seconds" =~ ^[0-9]+$ ]] || { [[ -n "$runs" ]] && ! [[ "$runs" =~ ^[0-9]+$ ]]; }; then
  echo "usage: tests/fuzz/run.sh [SECONDS] [RUNS]" >&2
  exit 2
fi

packages=(clang libclang-rt-dev cmake make libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev libyaml-cpp-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  if [[ $(id -u) -ne 0 ]]; then
    echo "The fuzz targets need these Debian packages. Install them, then run this command again:" >&2
    echo "  sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  echo "== installing: ${missing[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
fi

build=build-fuzz
CC=clang CXX=clang++ cmake -S . -B "$build" -DPLUME_BUILD_FUZZ=ON -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j"$(nproc)"

# Each target, the dictionary it mutates with, and which files of tests/data seed it.
targets=(fuzz_obj_mesh fuzz_obj_strands fuzz_hair fuzz_ply_ascii fuzz_ply_binary fuzz_usda fuzz_groom fuzz_roots fuzz_lifts)
declare -A dict=([fuzz_obj_mesh]=obj [fuzz_obj_strands]=obj [fuzz_hair]=hair [fuzz_ply_ascii]=ply
                 [fuzz_ply_binary]=ply [fuzz_usda]=usda [fuzz_groom]=yaml [fuzz_roots]=roots [fuzz_lifts]=lifts)
seeds_of() {
  case "$1" in
    fuzz_obj_mesh | fuzz_obj_strands) find tests/data -name '*.obj' ;;
    fuzz_hair) find tests/data -name '*.hair' ;;
    fuzz_ply_ascii) grep -rlas --include='*.ply' '^format ascii' tests/data || true ;;
    fuzz_ply_binary) grep -rLas --include='*.ply' '^format ascii' tests/data || true ;;
    fuzz_usda) find tests/data -name '*.usda' ;;
    fuzz_groom) find tests/data -name '*.yaml' ;;
    fuzz_roots) find tests/data -name '*.txt' ;;
    fuzz_lifts) find tests/data -name '*.lifts' ;;
  esac
}

mkdir -p "$build/findings" "$build/logs"
status=0
rows=()
for target in "${targets[@]}"; do
  seeds="$build/seeds/$target"
  rm -rf "$seeds"
  mkdir -p "$seeds" "$build/corpus/$target"
  seeds_of "$target" | while read -r file; do cp "$file" "$seeds/"; done
  before=$(find "$build/findings" -name "$target-*" | wc -l)
  options=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=4096
           -dict="tests/fuzz/dicts/${dict[$target]}.dict" -artifact_prefix="$build/findings/$target-"
           -print_final_stats=1)
  [[ -n "$runs" ]] && options+=(-runs="$runs")
  echo "== $target: ${seconds} s${runs:+ or $runs inputs}"
  start=$(date +%s)
  code=0
  "$build/tests/fuzz/$target" "${options[@]}" "$build/corpus/$target" "$seeds" >"$build/logs/$target.log" 2>&1 || code=$?
  elapsed=$(( $(date +%s) - start ))
  executed=$(sed -n 's/^stat::number_of_executed_units: *//p' "$build/logs/$target.log" | tail -1)
  corpus=$(find "$build/corpus/$target" -type f | wc -l)
  found=$(( $(find "$build/findings" -name "$target-*" | wc -l) - before ))
  if ((code != 0 && found == 0)); then found=1; fi  # a failure libFuzzer wrote no input for
  if ((found > 0)); then
    status=1
    echo "   finding: see $build/logs/$target.log and $build/findings/$target-*"
  fi
  rows+=("$(printf '%-18s %12s %8s %8s %9s' "$target" "${executed:-?}" "$elapsed" "$corpus" "$found")")
done

echo
printf '%-18s %12s %8s %8s %9s\n' target inputs seconds corpus findings
printf '%s\n' "${rows[@]}"
exit "$status"
