// Feather types blended (seed 001 sec. 4.2.3): every parameter interpolated, and the key barbs
// interpolated after the shorter lists are inflated to the same positions (Fig. 5).
#pragma once

#include <span>
#include <vector>

#include "groom/feather_desc.h"

namespace plume::feathers {

/// Key-barb lists of several feathers made the same length (Fig. 5): each completed list
/// (complete_key_barbs) gets a key barb at every position any list has, its own barb there (eq. 1),
/// so the lists pair up index by index. A position where some list has a step (several key barbs)
/// appears as often in every list, the other lists repeating their barb there. Inflating leaves each
/// feather's barbs as they were (eq. 1 is linear between key barbs).
std::vector<std::vector<KeyBarb>> inflate_key_barbs(std::span<const std::vector<KeyBarb>> completed_lists);

/// The key barbs of a blend: `lists` inflated, then each key barb's control vertices (elevated to the
/// largest degree among its partners), plumulaceous and open factors blended with `weights`.
/// Weights sum to 1; a list blended with copies of itself is returned as it is, to the bit.
std::vector<KeyBarb> blend_key_barbs(std::span<const std::vector<KeyBarb>> completed_lists,
                                     std::span<const float> weights);

/// A blend of feather types: lengths, widths, curvatures, spacings, angles, barb lengths (silhouettes
/// blended as functions, on the union of their points), the afterfeather's size, and each vane's key
/// barbs (blend_key_barbs of the completed lists). `weights` sum to 1, one per template; the name is
/// the heaviest template's. Blending a template with itself gives its feather back.
FeatherTemplate blend_templates(std::span<const FeatherTemplate *const> templates, std::span<const float> weights);

}  // namespace plume::feathers
