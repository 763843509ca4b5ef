// Feather growth (seed 001 sec. 4.2.4, Fig. 6): the parameters interpolated on a staggered schedule
// from a bare shaft to the adult feather.
#pragma once

#include "groom/feather_desc.h"

namespace plume::feathers {

/// The schedule, as fractions of development (Fig. 6, our reading of it):
/// - [0, 0.3]   the shaft grows: calamus and rachis lengths and the rachis width from 0 to the adult's;
/// - [0.3, 0.5] the barbs lengthen from 0 to the adult's length (silhouette);
/// - [0.3, 0.8] the barbs are three temporary straight key barbs: one at the base still in the sheath
///              (along the rachis), one at the tip, and one migrating from the tip to the base: the
///              sheath's front. Barbs above it have opened to the vane's angle (tip to base), barbs
///              below it open progressively toward it;
/// - [0.8, 1]   the temporary key barbs blend into the adult's (the extra barbs at the base and tip
///              go), and the rachis curvature grows to the adult's.
/// Stage 1 (or more) is the adult exactly.
inline constexpr float growth_shaft_end = 0.3f;
inline constexpr float growth_barbs_end = 0.5f;
inline constexpr float growth_sheath_end = 0.8f;

/// The feather at `stage` in [0, 1] of its development. Barb positions are not changed: a feather
/// keeps the adult's barbs as it grows (make_shape takes them from the adult).
FeatherTemplate grown_template(const FeatherTemplate &adult, float stage);

}  // namespace plume::feathers
