#!/usr/bin/env bash
# Plume's two commands:
#   ./dev.sh demo   install what is missing, build (Release), regrow the default groom into out/
#   ./dev.sh test   install what is missing, build (Release), run the whole test suite
set -euo pipefail
cd "$(dirname "$0")"

mode=${1:-}
if [[ "$mode" != demo && "$mode" != test ]]; then
  echo "usage: ./dev.sh demo | test" >&2
  exit 2
fi

packages=(cmake make g++ libeigen3-dev libnanoflann-dev libcgal-dev libgmp-dev libmpfr-dev catch2
          libyaml-cpp-dev libcli11-dev libpng-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# The test suite loads written USD files with a reader nobody here wrote (tinyusdz, kept in
# tests/third_party, under Node).
if [[ "$mode" == test ]] && ! command -v node >/dev/null 2>&1; then missing+=(nodejs); fi

# ---- The 3D viewer (plume view): three.js and esbuild come from npm, pinned by
# viewer/package-lock.json and bundled into plume at build time, so both commands need Node and
# npm; the test suite opens a written page in Debian's Chromium (headless, offline).
if ! command -v node >/dev/null 2>&1 && [[ " ${missing[*]} " != *" nodejs "* ]]; then missing+=(nodejs); fi
command -v npm >/dev/null 2>&1 || missing+=(npm)
if [[ "$mode" == test ]] && ! command -v chromium >/dev/null 2>&1; then missing+=(chromium); fi
# ---- end of the viewer's packages
if ((${#missing[@]})); then
  if [[ $(id -u) -ne 0 ]]; then
    echo "Plume needs these Debian packages. Install them, then run this command again:" >&2
    echo "  sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  echo "== installing: ${missing[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
fi

# ---- The viewer's npm packages, as viewer/package-lock.json pins them (again when it changes).
if [[ ! viewer/node_modules/.package-lock.json -nt viewer/package-lock.json ]]; then
  echo "== npm ci in viewer/ (three.js, esbuild)"
  (cd viewer && npm ci --no-audit --no-fund --loglevel=error)
fi
# ---- end of the viewer's npm packages

jobs=$(nproc)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"

if [[ "$mode" == demo ]]; then
  groom=grooms/sintel/sintel.groom.yaml
  echo "== regrowing $groom, frames 1-48 (30,000 strands, dynamics), into out/sintel/"
  start=$(date +%s)
  build/app/plume regrow "$groom" --frames 1-48 --out out/sintel/hair.####.usda \
    --preview out/sintel/preview.####.png --preview-every 6
  seconds=$(( $(date +%s) - start ))
  echo "== done in ${seconds} s: out/sintel/hair.0001.usda .. hair.0048.usda ($(du -sh out/sintel | cut -f1) in all)," \
       "previews out/sintel/preview.*.png (every 6 frames)"
  echo "== the 3D view: every 4th frame into out/sintel/view.html (open it in a browser)"
  start=$(date +%s)
  build/app/plume view "$groom" --frames 1-48:4 --out out/sintel/view.html
  echo "== done in $(( $(date +%s) - start )) s: out/sintel/view.html ($(du -h out/sintel/view.html | cut -f1))"
else
  ctest --test-dir build --output-on-failure -j"$jobs"
fi
