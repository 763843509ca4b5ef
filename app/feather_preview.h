// Feathers in the preview picture: vanes drawn as shaded triangles over the emitter, rachis and
// barbs as strands, through the preview rasteriser (app/preview.h).
#pragma once

#include "app/preview.h"
#include "feathers/coat.h"
#include "groom/mesh.h"
#include "groom/strand_set.h"

namespace plume {

/// The emitter `mesh` with a frame of feathers: vane triangles in a dark tone of the style's hair
/// colour, rachis and barbs as strands of that colour (each feather's tone hashed from its id), and
/// the guide stems when `stems` is not null. Deterministic, like render_preview.
Image render_feather_preview(const PreviewCamera &camera, const Mesh &mesh, const feathers::CoatFrame &feathers,
                             const StrandSet *stems, PreviewStyle style);

/// The preview camera of a feather groom: fitted to the rest emitter and a rest frame's feathers
/// (`curves`), so that every frame is seen from the same place, looking from `angle`.
PreviewCamera feather_camera(const Mesh &rest_mesh, const StrandSet &curves, const CameraAngle &angle = {});

}  // namespace plume
