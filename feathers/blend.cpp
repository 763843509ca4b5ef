#include "feathers/blend.h"

#include <algorithm>

#include "feathers/feather.h"
#include "groom/error.h"

namespace plume::feathers {

namespace {

/// x_0 + sum_{i >= 1} w_i (x_i - x_0): the weighted sum for weights summing to 1, written so that
/// equal values blend back to themselves to the bit.
template <class Value, class Get>
Value blended(size_t count, std::span<const float> weights, const Get &get) {
  const Value first = get(0);
  Value sum = first;
  for (size_t i = 1; i < count; ++i) sum += weights[i] * (get(i) - first);
  return sum;
}

KeyBarb key_from_blend(const KeyBarbBlend &blend, float position) {
  KeyBarb key;
  key.position = position;
  key.points.assign(blend.polygon.points.begin(), blend.polygon.points.begin() + blend.polygon.count);
  key.plumulaceous = blend.plumulaceous;
  key.open = blend.open;
  return key;
}

/// The values of a ramp just below and just above t: equal unless the ramp steps at t.
std::pair<float, float> ramp_sides(const Ramp &ramp, float t) {
  const auto first = std::lower_bound(ramp.t.begin(), ramp.t.end(), t);
  const auto last = std::upper_bound(ramp.t.begin(), ramp.t.end(), t);
  if (first == last) {
    const float v = ramp.at(t);
    return {v, v};
  }
  return {ramp.value[size_t(first - ramp.t.begin())], ramp.value[size_t(last - ramp.t.begin()) - 1]};
}

/// The vanes' barb lengths blended as functions of t: a constant when every vane has one, else a
/// silhouette on the union of the silhouettes' points (piecewise linear functions add exactly there),
/// each step kept as two points.
void blend_barb_lengths(std::span<const VaneDesc *const> vanes, std::span<const float> weights, VaneDesc &r_vane) {
  const size_t n = vanes.size();
  r_vane.barb_length = std::max(0.0f, blended<float>(n, weights, [&](size_t i) { return vanes[i]->barb_length; }));
  std::vector<float> knots;
  for (const VaneDesc *vane : vanes) knots.insert(knots.end(), vane->silhouette.t.begin(), vane->silhouette.t.end());
  r_vane.silhouette = Ramp{};
  if (knots.empty()) return;
  std::sort(knots.begin(), knots.end());
  knots.erase(std::unique(knots.begin(), knots.end()), knots.end());
  auto side = [&](size_t i, float t, bool above) {
    const VaneDesc &vane = *vanes[i];
    if (vane.silhouette.t.empty()) return vane.barb_length;
    const std::pair<float, float> sides = ramp_sides(vane.silhouette, t);
    return above ? sides.second : sides.first;
  };
  for (const float t : knots) {
    // Lengths are never negative, not even by rounding.
    const float below = std::max(0.0f, blended<float>(n, weights, [&](size_t i) { return side(i, t, false); }));
    const float above = std::max(0.0f, blended<float>(n, weights, [&](size_t i) { return side(i, t, true); }));
    r_vane.silhouette.t.push_back(t);
    r_vane.silhouette.value.push_back(below);
    if (above != below) {
      r_vane.silhouette.t.push_back(t);
      r_vane.silhouette.value.push_back(above);
    }
  }
}

}  // namespace

std::vector<std::vector<KeyBarb>> inflate_key_barbs(std::span<const std::vector<KeyBarb>> lists) {
  // Every position any list has, with the most key barbs any list has there.
  std::vector<std::pair<float, size_t>> positions;
  for (const std::vector<KeyBarb> &list : lists) {
    for (size_t k = 0; k < list.size();) {
      size_t run = 1;
      while (k + run < list.size() && list[k + run].position == list[k].position) ++run;
      const auto at = std::lower_bound(positions.begin(), positions.end(), list[k].position,
                                       [](const std::pair<float, size_t> &p, float v) { return p.first < v; });
      if (at != positions.end() && at->first == list[k].position)
        at->second = std::max(at->second, run);
      else
        positions.insert(at, {list[k].position, run});
      k += run;
    }
  }
  std::vector<std::vector<KeyBarb>> inflated(lists.size());
  for (size_t l = 0; l < lists.size(); ++l) {
    const std::vector<KeyBarb> &list = lists[l];
    std::vector<KeyBarb> &out = inflated[l];
    size_t k = 0;
    for (const auto &[position, multiplicity] : positions) {
      const size_t start = out.size();
      while (k < list.size() && list[k].position == position) out.push_back(list[k++]);
      if (out.size() == start) out.push_back(key_from_blend(interpolate_key_barbs(list, position), position));
      while (out.size() - start < multiplicity) out.push_back(out.back());
    }
  }
  return inflated;
}

std::vector<KeyBarb> blend_key_barbs(std::span<const std::vector<KeyBarb>> lists, std::span<const float> weights) {
  if (lists.empty()) return {};
  if (weights.size() != lists.size()) throw InternalError("blend_key_barbs: one weight per list expected");
  const std::vector<std::vector<KeyBarb>> inflated = inflate_key_barbs(lists);
  const size_t n = inflated.size();
  std::vector<KeyBarb> out(inflated[0].size());
  for (size_t j = 0; j < out.size(); ++j) {
    int count = 0;
    for (const std::vector<KeyBarb> &list : inflated) count = std::max(count, int(list[j].points.size()));
    std::vector<ControlPolygon> polygons(n);
    for (size_t i = 0; i < n; ++i) {
      const KeyBarb &key = inflated[i][j];
      polygons[i].count = int(key.points.size());
      std::copy(key.points.begin(), key.points.end(), polygons[i].points.begin());
      elevate_to(polygons[i], count);
    }
    KeyBarb &key = out[j];
    key = inflated[0][j];
    key.points.resize(size_t(count));
    for (int c = 0; c < count; ++c)
      key.points[size_t(c)] =
          blended<Eigen::Vector3f>(n, weights, [&](size_t i) -> Eigen::Vector3f { return polygons[i].points[size_t(c)]; });
    // Convex blends of values in [0, 1], kept there against rounding.
    key.plumulaceous =
        std::clamp(blended<float>(n, weights, [&](size_t i) { return inflated[i][j].plumulaceous; }), 0.0f, 1.0f);
    key.open = std::clamp(blended<float>(n, weights, [&](size_t i) { return inflated[i][j].open; }), 0.0f, 1.0f);
  }
  return out;
}

FeatherTemplate blend_templates(std::span<const FeatherTemplate *const> templates, std::span<const float> weights) {
  if (templates.empty() || weights.size() != templates.size())
    throw InternalError("blend_templates: one weight per template expected");
  const size_t n = templates.size();
  const size_t heaviest = size_t(std::max_element(weights.begin(), weights.end()) - weights.begin());
  FeatherTemplate out = *templates[heaviest];
  // Every scalar parameter's valid range is an interval, so convex blends stay in it up to rounding,
  // which the clamp to the templates' own range removes.
  auto scalar = [&](float FeatherTemplate::*field) {
    float lo = templates[0]->*field, hi = lo;
    for (size_t i = 1; i < n; ++i) {
      lo = std::min(lo, templates[i]->*field);
      hi = std::max(hi, templates[i]->*field);
    }
    out.*field = std::clamp(blended<float>(n, weights, [&](size_t i) { return templates[i]->*field; }), lo, hi);
  };
  for (float FeatherTemplate::*field :
       {&FeatherTemplate::calamus_length, &FeatherTemplate::calamus_width_ratio, &FeatherTemplate::rachis_length,
        &FeatherTemplate::rachis_width, &FeatherTemplate::curvature_side, &FeatherTemplate::curvature_front,
        &FeatherTemplate::spacing_base, &FeatherTemplate::spacing_tip, &FeatherTemplate::barb_width,
        &FeatherTemplate::afterfeather})
    scalar(field);
  for (VaneDesc FeatherTemplate::*vane_field : {&FeatherTemplate::left, &FeatherTemplate::right}) {
    std::vector<const VaneDesc *> vanes(n);
    std::vector<std::vector<KeyBarb>> lists(n);
    for (size_t i = 0; i < n; ++i) {
      vanes[i] = &(templates[i]->*vane_field);
      lists[i] = complete_key_barbs(vanes[i]->key_barbs);
    }
    VaneDesc &vane = out.*vane_field;
    vane.angle_base = std::clamp(blended<float>(n, weights, [&](size_t i) { return vanes[i]->angle_base; }), 0.0f, 180.0f);
    vane.angle_tip = std::clamp(blended<float>(n, weights, [&](size_t i) { return vanes[i]->angle_tip; }), 0.0f, 180.0f);
    blend_barb_lengths(vanes, weights, vane);
    vane.key_barbs = blend_key_barbs(lists, weights);
  }
  return out;
}

}  // namespace plume::feathers
