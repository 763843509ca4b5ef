#!/bin/sh
# Renders the feather gallery of docs/feathers.md (docs/gallery/*.png) and the bird of the README
# (docs/bird.png) with plume itself, from the grooms in this folder and grooms/bird. A test renders
# them again and compares them with the pictures kept in docs/: run this after changing how feathers
# are built or drawn.
#
#   grooms/gallery/make_gallery.sh [PLUME [DOCS]]    # defaults: build/app/plume, docs/
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
plume=${1:-$root/build/app/plume}
docs=${2:-$root/docs}
mkdir -p "$docs/gallery"
for feather in contour down flight semi_plume; do
  "$plume" preview "$here/$feather.groom.yaml" --camera top --size 600 --out "$docs/gallery/$feather.png"
done
# From below and behind: the afterfeather under the base of the semi-plume.
"$plume" preview "$here/semi_plume.groom.yaml" --camera 180,-70 --size 600 --out "$docs/gallery/semi_plume_below.png"
"$plume" preview "$here/growth.groom.yaml" --camera top --size 800 --out "$docs/gallery/growth.png"
# The bird at frame 24: the left wing open, the neck bent, the stems simulated from frame 1.
"$plume" preview "$root/grooms/bird/bird.groom.yaml" --frame 24 --size 800 --out "$docs/bird.png"
