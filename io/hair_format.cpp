// Cem Yuksel's .hair: a 128-byte little-endian header, then the arrays its flags announce
// (segments u16[hairs], points f32[3 * points], thickness f32[points], transparency f32[points],
// colors f32[3 * points]), in that order.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <tuple>

#include "io/file_scan.h"
#include "io/strand_formats.h"

namespace plume::io::detail {
namespace {

constexpr size_t kHeaderBytes = 128;
constexpr size_t kInfoBytes = 88;
enum HairArrays : uint32_t { kSegments = 1, kPoints = 2, kThickness = 4, kTransparency = 8, kColors = 16 };

}  // namespace

StrandSet read_hair(const std::string &path) {
  const std::string bytes = read_file_bytes(path);
  const ByteCursor in(bytes, path);
  if (bytes.size() < kHeaderBytes)
    in.fail(0, "header: expected 128 bytes, file has " + std::to_string(bytes.size()));
  if (std::memcmp(bytes.data(), "HAIR", 4) != 0)
    in.fail(0, "magic: expected \"HAIR\", got " + quoted(std::string_view(bytes.data(), 4)));
  const uint32_t hair_num = in.get<uint32_t>(4);
  const uint32_t point_num = in.get<uint32_t>(8);
  const uint32_t arrays = in.get<uint32_t>(12);
  const uint32_t default_segments = in.get<uint32_t>(16);
  if (!(arrays & kPoints)) in.fail(12, "arrays: expected the points bit (2) to be set, got " + std::to_string(arrays));
  if (arrays > 31) in.fail(12, "arrays: expected a combination of bits 1..16, got " + std::to_string(arrays));

  // Every array must fit in the file before anything is allocated.
  size_t offset = kHeaderBytes;
  const size_t segments_at = offset;
  if (arrays & kSegments) {
    in.require(offset, hair_num, 2, "segments");
    offset += size_t(hair_num) * 2;
  }
  const size_t points_at = offset;
  in.require(offset, point_num, 12, "points");
  offset += size_t(point_num) * 12;
  const size_t thickness_at = offset;
  for (const auto &[bit, item_bytes, name] : {std::tuple{kThickness, 4, "thickness"},
                                               std::tuple{kTransparency, 4, "transparency"},
                                               std::tuple{kColors, 12, "colors"}})
    if (arrays & bit) {
      in.require(offset, point_num, item_bytes, name);
      offset += size_t(point_num) * item_bytes;
    }
  if (offset != bytes.size())
    in.fail(offset, "expected the file to end here after the arrays the header announces, got " +
                        std::to_string(bytes.size() - offset) + " more bytes");

  // Segments must add up to the point count: points = sum(segments + 1).
  uint64_t counted_points = 0;
  if (arrays & kSegments) {
    for (uint32_t h = 0; h < hair_num; ++h) {
      const uint16_t segments = in.get<uint16_t>(segments_at + 2 * size_t(h));
      if (segments == 0) in.fail(segments_at + 2 * size_t(h), "segments[" + std::to_string(h) + "]: expected at least 1, got 0");
      counted_points += uint64_t(segments) + 1;
    }
  } else {
    if (default_segments == 0 && hair_num > 0)
      in.fail(16, "default segments: expected at least 1 when there is no segments array, got 0");
    counted_points = uint64_t(hair_num) * (uint64_t(default_segments) + 1);
  }
  if (counted_points != point_num)
    in.fail(arrays & kSegments ? segments_at : 16,
            "segments: expected to add up to the point count " + std::to_string(point_num) + " (points = sum of segments + 1), got " +
                std::to_string(counted_points));

  StrandSet strands;
  strands.offsets.resize(size_t(hair_num) + 1);
  strands.offsets[0] = 0;
  for (uint32_t h = 0; h < hair_num; ++h) {
    const uint64_t segments = (arrays & kSegments) ? in.get<uint16_t>(segments_at + 2 * size_t(h)) : default_segments;
    strands.offsets[h + 1] = strands.offsets[h] + int64_t(segments) + 1;
  }
  strands.positions.resize(point_num);
  for (uint32_t p = 0; p < point_num; ++p)
    for (int axis = 0; axis < 3; ++axis) {
      const size_t at = points_at + 12 * size_t(p) + 4 * size_t(axis);
      const float value = in.get<float>(at);
      if (!std::isfinite(value))
        in.fail(at, "points[" + std::to_string(p) + "]." + "xyz"[axis] + ": expected a finite number, got " + std::to_string(value));
      strands.positions[p][axis] = value;
    }
  if (arrays & kThickness) {
    strands.widths.resize(point_num);
    for (uint32_t p = 0; p < point_num; ++p) {
      const size_t at = thickness_at + 4 * size_t(p);
      const float width = in.get<float>(at);
      if (!std::isfinite(width) || width < 0.0f)
        in.fail(at, "thickness[" + std::to_string(p) + "]: expected a finite number >= 0, got " + std::to_string(width));
      strands.widths[p] = width;
    }
  }
  strands.ids.resize(hair_num);
  for (uint32_t h = 0; h < hair_num; ++h) strands.ids[h] = h;
  return strands;
}

void write_hair(AtomicFile &file, const StrandSet &strands, const StrandWriteOptions &options) {
  constexpr size_t kMaxU32 = std::numeric_limits<uint32_t>::max();
  if (strands.strand_count() > kMaxU32 || strands.point_count() > kMaxU32)
    throw InputError(FileLoc{file.path()}, ".hair holds at most 2^32-1 strands and points, got " +
                                               std::to_string(strands.strand_count()) + " strands, " +
                                               std::to_string(strands.point_count()) + " points");
  for (size_t s = 0; s < strands.strand_count(); ++s)
    if (strands.points_in(s) - 1 > 65535)
      throw InputError(FileLoc{file.path()}, "strand " + std::to_string(s) + ": .hair holds at most 65,535 segments per strand, got " +
                                                 std::to_string(strands.points_in(s) - 1));
  const bool has_widths = !strands.widths.empty();
  char header[kHeaderBytes] = {};
  std::memcpy(header, "HAIR", 4);
  const uint32_t hair_num = uint32_t(strands.strand_count());
  const uint32_t point_num = uint32_t(strands.point_count());
  const uint32_t arrays = kSegments | kPoints | (has_widths ? kThickness : 0u);
  const uint32_t default_segments = hair_num > 0 ? uint32_t(strands.points_in(0) - 1) : 0u;
  const float default_thickness = options.constant_width;
  const float default_transparency = 0.0f;
  const float default_color[3] = {0.0f, 0.0f, 0.0f};
  std::memcpy(header + 4, &hair_num, 4);
  std::memcpy(header + 8, &point_num, 4);
  std::memcpy(header + 12, &arrays, 4);
  std::memcpy(header + 16, &default_segments, 4);
  std::memcpy(header + 20, &default_thickness, 4);
  std::memcpy(header + 24, &default_transparency, 4);
  std::memcpy(header + 28, default_color, 12);
  std::memcpy(header + 40, options.comment.data(), std::min(options.comment.size(), kInfoBytes - 1));
  file.write(header, kHeaderBytes);

  std::vector<uint16_t> segments(hair_num);
  for (uint32_t h = 0; h < hair_num; ++h) segments[h] = uint16_t(strands.points_in(h) - 1);
  file.write(segments.data(), segments.size() * sizeof(uint16_t));
  static_assert(sizeof(Eigen::Vector3f) == 12, "points are written as packed float triples");
  file.write(strands.positions.data(), strands.positions.size() * sizeof(Eigen::Vector3f));
  if (has_widths) file.write(strands.widths.data(), strands.widths.size() * sizeof(float));
}

}  // namespace plume::io::detail
