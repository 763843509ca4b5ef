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

/// Where a camera looks from, around the subject: turned `azimuth_degrees` about the up axis from
/// the front (0: the front view; 90: from the right of the front view, which shows the subject's
/// left side, as Blender's and Maya's right/side views; 180: from behind) and raised
/// `elevation_degrees` above the horizon (90: from above). The default is the three-quarter view.
struct CameraAngle {
  float azimuth_degrees = 35.0f;
  float elevation_degrees = 10.0f;
};

/// Parses a camera choice: front, back, left, right, top, three-quarter, or an orbit angle in
/// degrees, "AZ" (at the default elevation) or "AZ,EL" (EL in [-90, 90]). The top view has the
/// subject's front at the bottom of the picture. Throws InputError naming `what` otherwise.
CameraAngle parse_camera_angle(const std::string &text, const std::string &what);

/// A camera looking at the centre of `bounds` from `angle` (around `up`, from the side `front`
/// faces), as close as it can be with every corner of `bounds` inside the view (6% margin).
/// `front` need not be orthogonal to `up`; the picture's up is `up` tilted by the elevation, so a
/// view from straight above is well defined.
PreviewCamera fit_camera(const Eigen::AlignedBox3f &bounds, const CameraAngle &angle = {},
                         const Eigen::Vector3f &up = Eigen::Vector3f::UnitY(),
                         const Eigen::Vector3f &front = Eigen::Vector3f::UnitZ());

/// `count` cameras turning around `up`: azimuths start.azimuth + 360 i / count at start's
/// elevation, all at the same distance from the centre of `bounds` (the farthest any of them
/// needs), so that the subject keeps its size from one view to the next.
std::vector<PreviewCamera> turntable_cameras(const Eigen::AlignedBox3f &bounds, int count, const CameraAngle &start = {},
                                             const Eigen::Vector3f &up = Eigen::Vector3f::UnitY(),
                                             const Eigen::Vector3f &front = Eigen::Vector3f::UnitZ());

/// The most memory a band of the supersampled raster takes: up to max_preview_size (groom_desc.h)
/// pixels a side, the image and its PNG are held whole and the supersampled raster is drawn in bands.
inline constexpr size_t kPreviewBandBytes = size_t(64) << 20;

/// Colours are linear RGB in [0, 1]; the image is written sRGB-encoded.
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

/// The plain hair colour of the strand with stable id `id`: style.hair_color with a per-strand
/// tone between 0.7x and 1.3x, hashed from the id so that it holds from frame to frame.
Eigen::Vector3f plain_hair_color(const PreviewStyle &style, uint64_t id);

/// How the strands are painted, when not in the plain hair colour.
struct StrandPaint {
  /// Empty, or one linear RGB base colour per strand (shaded as hair).
  std::vector<Eigen::Vector3f> colors;
  /// Empty, or one flag per strand: flagged strands are drawn over the others, hidden only by the
  /// skin (as the guides are), so that a few strands the checker reports are seen in a full head.
  std::vector<uint8_t> on_top;
  /// Empty, or one linear RGB albedo per triangle of the mesh, replacing the skin colour (a
  /// feather's vanes drawn among the skin's triangles).
  std::vector<Eigen::Vector3f> triangle_colors;
};

/// 8-bit RGB, rows top to bottom: width * height * 3 bytes.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;
};

/// Bounds of the mesh's vertices and every strand point.
Eigen::AlignedBox3f scene_bounds(const Mesh &mesh, const StrandSet &strands);

/// Renders `mesh` (vertex normals computed) shaded as skin, and `strands`; when `guides` is not
/// null, the guides are drawn in the guide colour over the strands, hidden only by the skin.
/// The first third of every strand is darkened (hair near the scalp lies under other hair), but
/// the skin is never painted: where strands are sparse, the skin shows between them.
/// Deterministic: the same inputs give the same pixels.
Image render_preview(const PreviewCamera &camera, const Mesh &mesh, const StrandSet &strands,
                     const StrandSet *guides, const PreviewStyle &style = {}, const StrandPaint &paint = {});

/// The most pictures a sheet holds, and the longest side of a sheet, pixels.
inline constexpr int kMaxSheetImages = 144;
inline constexpr int kMaxSheetSide = 16384;

/// Lays `images` (all of one size) out in rows of `columns`, left to right and top to bottom; a
/// last row that is not full is filled with the first image's top-left pixel colour.
Image tile_images(const std::vector<Image> &images, int columns);

/// Encodes `image` as an 8-bit RGB PNG (libpng) written atomically to `path`.
/// Throws InputError when the file cannot be written.
void write_png(const std::string &path, const Image &image);

}  // namespace plume
