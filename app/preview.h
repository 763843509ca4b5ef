// The preview picture: a small software rasteriser that draws the shaded emitter and the strands
// (anti-aliased by supersampling, depth-tested, Kajiya-Kay hair shading) and writes a PNG.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "groom/groom_desc.h"
#include "groom/mesh.h"
#include "groom/strand_set.h"

namespace plume {

/// A pinhole camera. `up` need not be orthogonal to the view direction.
struct PreviewCamera {
  Eigen::Vector3f eye = Eigen::Vector3f(0.0f, 0.0f, 10.0f);
  Eigen::Vector3f target = Eigen::Vector3f::Zero();
  Eigen::Vector3f up = Eigen::Vector3f::UnitY();
  float fov_y_degrees = 30.0f;
};

/// A camera looking at the centre of `bounds` from a three-quarter front view: from the `front`
/// side (the direction the subject faces), turned `yaw_degrees` about `up` and raised
/// `pitch_degrees`, as close as it can be with every corner of `bounds` inside the view (6% margin).
PreviewCamera fit_camera(const Eigen::AlignedBox3f &bounds, const Eigen::Vector3f &up = Eigen::Vector3f::UnitY(),
                         const Eigen::Vector3f &front = Eigen::Vector3f::UnitZ(), float yaw_degrees = 35.0f,
                         float pitch_degrees = 10.0f);

/// The most memory a band of the supersampled raster takes: up to max_preview_size (groom_desc.h)
/// pixels a side, the image and its PNG are held whole and the supersampled raster is drawn in bands.
inline constexpr size_t kPreviewBandBytes = size_t(64) << 20;

/// Colours are linear RGB in [0, 1]; the image is written gamma-encoded (sRGB-like, 1/2.2).
struct PreviewStyle {
  int size = 800;        // square image, pixels, in [1, max_preview_size]
  int supersample = 3;   // strands and edges are drawn at size * supersample, then box-filtered
  int strand_brush = 3;  // strand width in supersampled pixels
  Eigen::Vector3f hair_color = Eigen::Vector3f(0.16f, 0.055f, 0.022f);
  Eigen::Vector3f guide_color = Eigen::Vector3f(0.1f, 0.85f, 1.0f);
  Eigen::Vector3f skin_color = Eigen::Vector3f(0.62f, 0.42f, 0.33f);
  Eigen::Vector3f background_top = Eigen::Vector3f(0.035f, 0.04f, 0.05f);
  Eigen::Vector3f background_bottom = Eigen::Vector3f(0.008f, 0.008f, 0.012f);
};

/// 8-bit RGB, rows top to bottom: width * height * 3 bytes.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;
};

/// Bounds of the mesh's vertices and every strand point.
Eigen::AlignedBox3f scene_bounds(const Mesh &mesh, const StrandSet &strands);

/// Renders `mesh` (vertex normals computed) and `strands`, and, when `guides` is not null, the
/// guides drawn over them in the guide colour (still depth-tested against the mesh).
/// `scalp_triangles` (empty, or one flag per triangle) marks the skin the hair grows from: it is
/// drawn in a dark hair tone, as the skin seen between strands would look under real hair.
/// Deterministic: the same inputs give the same pixels.
Image render_preview(const PreviewCamera &camera, const Mesh &mesh, const StrandSet &strands,
                     const StrandSet *guides, const PreviewStyle &style = {},
                     const std::vector<bool> &scalp_triangles = {});

/// One flag per triangle of `mesh`: true where one of `root_triangles` lies.
std::vector<bool> scalp_mask(const Mesh &mesh, const std::vector<int32_t> &root_triangles);

/// Encodes `image` as an 8-bit RGB PNG (libpng) written atomically to `path`.
/// Throws InputError when the file cannot be written.
void write_png(const std::string &path, const Image &image);

}  // namespace plume
