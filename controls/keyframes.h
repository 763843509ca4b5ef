// Keyed values at a frame: held before the first key and after the last, linear or monotone cubic
// between keys.
#pragma once

#include <Eigen/Core>

#include "groom/control_desc.h"

namespace plume::controls {

/// The value of `keyed` at `frame`. `keyed` must not be empty. Smooth keys use cubic Hermite
/// segments whose tangents are Fritsch and Butland's weighted harmonic mean of the two secants
/// around a key (0 where they differ in sign, and at the first and last key, so the held ends join
/// smoothly): the curve is C1 and between two keys never leaves the interval of their values.
float value_at(const Keyed<float> &keyed, double frame);
/// The same for each component of a vector.
Eigen::Vector3f value_at(const Keyed<Eigen::Vector3f> &keyed, double frame);

}  // namespace plume::controls
