#include "app/preview.h"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "groom/error.h"
#include "groom/roots.h"
#include "io/atomic_file.h"

namespace plume {

namespace {

constexpr float kPi = 3.14159265358979f;

// The camera's view basis and projection onto a square raster of `size` pixels.
struct Projector {
  Eigen::Vector3f eye, right, up, forward;
  float focal = 1.0f;  // pixels per unit of (x / z)
  float half = 0.0f;   // half the raster size, pixels
  float near = 1e-3f;

  Projector(const PreviewCamera &camera, int size) {
    eye = camera.eye;
    forward = (camera.target - camera.eye).normalized();
    right = forward.cross(camera.up).normalized();
    up = right.cross(forward);
    half = 0.5f * float(size);
    focal = half / std::tan(0.5f * camera.fov_y_degrees * kPi / 180.0f);
    near = 1e-4f * (camera.target - camera.eye).norm();
  }
  // (screen x, screen y, view depth); depth <= near means behind the camera.
  Eigen::Vector3f project(const Eigen::Vector3f &p) const {
    const Eigen::Vector3f d = p - eye;
    const float z = d.dot(forward);
    if (z <= near) return {0.0f, 0.0f, z};
    return {half + focal * d.dot(right) / z, half - focal * d.dot(up) / z, z};
  }
};

// A band of rows y_begin .. y_end() - 1 of the square raster of `size` x `size` pixels.
struct Raster {
  int size = 0;
  int y_begin = 0;
  int rows = 0;
  std::vector<Eigen::Vector3f> color;  // linear RGB, rows * size
  std::vector<float> depth;            // view depth, +inf where empty
  /// The depth the overlays (guides, strands drawn on top) are tested against: the skin's, then
  /// the overlays' own.
  std::vector<float> overlay_depth;

  Raster(int size_, int y_begin_, int rows_, const PreviewStyle &style)
      : size(size_), y_begin(y_begin_), rows(rows_), color(size_t(rows_) * size_), depth(size_t(rows_) * size_) {
    std::fill(depth.begin(), depth.end(), std::numeric_limits<float>::infinity());
    for (int y = y_begin; y < y_end(); ++y) {
      const float a = float(y) / float(std::max(size - 1, 1));
      const Eigen::Vector3f c = (1.0f - a) * style.background_top + a * style.background_bottom;
      std::fill(color.begin() + index(0, y), color.begin() + index(0, y + 1), c);
    }
  }
  int y_end() const { return y_begin + rows; }
  /// Starts the overlays: they are hidden by what is drawn so far (the skin), not by what follows.
  void begin_overlays() { overlay_depth = depth; }
  /// The pixel (x, y) of the whole raster, y in [y_begin, y_end()).
  size_t index(int x, int y) const { return size_t(y - y_begin) * size_t(size) + size_t(x); }
};

// Lights are fixed relative to the camera so every view is lit the same way: a key light from the
// upper left in front of the subject, a dim fill from the right, and a rim light from behind.
struct Lights {
  Eigen::Vector3f key, fill, rim;
  explicit Lights(const Projector &proj) {
    key = (-0.55f * proj.right + 0.65f * proj.up - 0.55f * proj.forward).normalized();
    fill = (0.8f * proj.right + 0.1f * proj.up - 0.6f * proj.forward).normalized();
    rim = (0.2f * proj.right + 0.6f * proj.up + 0.8f * proj.forward).normalized();
  }
};

// `screen`: proj.project() of every mesh vertex. The whole mesh is skin, the scalp included.
// `triangle_colors`: empty, or an albedo per triangle in place of the skin colour.
void draw_mesh(const Mesh &mesh, const std::vector<Eigen::Vector3f> &screen, const Projector &proj,
               const Lights &lights, const PreviewStyle &style, const std::vector<Eigen::Vector3f> &triangle_colors,
               Raster &r_raster) {
  const int size = r_raster.size;
  for (size_t f = 0; f < mesh.triangle_count(); ++f) {
    const Eigen::Vector3f &albedo = f < triangle_colors.size() ? triangle_colors[f] : style.skin_color;
    const Eigen::Vector3i &tri = mesh.triangles[f];
    const Eigen::Vector3f &a = screen[tri[0]], &b = screen[tri[1]], &c = screen[tri[2]];
    if (a.z() <= proj.near || b.z() <= proj.near || c.z() <= proj.near) continue;
    const float area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (std::abs(area) < 1e-12f) continue;
    const int x0 = std::max(0, int(std::floor(std::min({a.x(), b.x(), c.x()}))));
    const int x1 = std::min(size - 1, int(std::ceil(std::max({a.x(), b.x(), c.x()}))));
    const float y_min = std::min({a.y(), b.y(), c.y()}), y_max = std::max({a.y(), b.y(), c.y()});
    if (y_max < float(r_raster.y_begin) - 1.0f || y_min > float(r_raster.y_end()) + 1.0f) continue;
    const int y0 = std::max(r_raster.y_begin, int(std::floor(y_min)));
    const int y1 = std::min(r_raster.y_end() - 1, int(std::ceil(y_max)));
    const Eigen::Vector3f inv_z(1.0f / a.z(), 1.0f / b.z(), 1.0f / c.z());
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const float px = float(x) + 0.5f, py = float(y) + 0.5f;
        // Screen-space barycentrics from the edge functions (either winding).
        float w0 = ((b.x() - px) * (c.y() - py) - (b.y() - py) * (c.x() - px)) / area;
        float w1 = ((c.x() - px) * (a.y() - py) - (c.y() - py) * (a.x() - px)) / area;
        float w2 = 1.0f - w0 - w1;
        if (w0 < 0.0f || w1 < 0.0f || w2 < 0.0f) continue;
        // Perspective-correct interpolation: 1/z is linear in screen space.
        const Eigen::Vector3f pw(w0 * inv_z[0], w1 * inv_z[1], w2 * inv_z[2]);
        const float sum = pw.sum();
        const float z = 1.0f / sum;
        const size_t pixel = r_raster.index(x, y);
        if (!(z < r_raster.depth[pixel])) continue;
        r_raster.depth[pixel] = z;
        const Eigen::Vector3f bary = pw / sum;
        Eigen::Vector3f n = (bary[0] * mesh.vertex_normals[tri[0]] + bary[1] * mesh.vertex_normals[tri[1]] +
                             bary[2] * mesh.vertex_normals[tri[2]]);
        if (n.squaredNorm() < 1e-20f) n = mesh.face_normal(f);
        n.normalize();
        const Eigen::Vector3f p = bary[0] * mesh.positions[tri[0]] + bary[1] * mesh.positions[tri[1]] +
                                  bary[2] * mesh.positions[tri[2]];
        const Eigen::Vector3f view = (proj.eye - p).normalized();
        if (n.dot(view) < 0.0f) n = -n;  // two-sided
        const float key = std::max(0.0f, n.dot(lights.key));
        const float fill = std::max(0.0f, n.dot(lights.fill));
        const float rim = std::pow(1.0f - std::max(0.0f, n.dot(view)), 3.0f) * std::max(0.0f, n.dot(lights.rim) + 0.3f);
        r_raster.color[pixel] = albedo * (0.08f + 0.85f * key + 0.25f * fill) +
                                Eigen::Vector3f(0.25f, 0.25f, 0.3f) * rim;
      }
    }
  }
}

// Kajiya-Kay: a fibre scatters light in the cone around its tangent T, so the diffuse term is
// sin(T, L) and the specular term is the cosine between the reflection cone and the view,
// sin(T, H)^p with H the half vector. `occlusion` darkens the inside of the hair near the roots.
Eigen::Vector3f shade_hair(const Eigen::Vector3f &tangent, const Eigen::Vector3f &view, const Lights &lights,
                           const Eigen::Vector3f &base, float occlusion) {
  auto sin_between = [](const Eigen::Vector3f &t, const Eigen::Vector3f &d) {
    const float c = t.dot(d);
    return std::sqrt(std::max(0.0f, 1.0f - c * c));
  };
  const float key = sin_between(tangent, lights.key);
  const float fill = sin_between(tangent, lights.fill);
  const Eigen::Vector3f half_key = (lights.key + view).normalized();
  const float spec = std::pow(sin_between(tangent, half_key), 90.0f);
  const float spec_wide = std::pow(sin_between(tangent, half_key), 12.0f);
  const Eigen::Vector3f diffuse = base * (0.06f + 0.9f * key + 0.2f * fill);
  const Eigen::Vector3f specular =
      0.07f * spec * Eigen::Vector3f(1.0f, 0.93f, 0.85f) + 0.5f * spec_wide * base;
  return occlusion * (diffuse + specular);
}

// Which strands a draw_strands() call draws, and how.
struct StrandLayer {
  const Eigen::Vector3f *colors = nullptr;  // one base colour per strand, or null: `color` for all
  Eigen::Vector3f color = Eigen::Vector3f::Zero();
  const uint8_t *on_top = nullptr;  // null: every strand; else only the strands whose flag equals `top`
  uint8_t top = 0;
  bool root_shadow = true;  // darken the first third of every strand
  bool overlay = false;     // tested against (and written to) the overlay depth
  int brush = 1;
};

// Draws the segments of `strands` (those `layer` selects) as lines of `brush` x `brush` raster
// pixels, depth-tested, within the rows of `r_raster`. Lines are stepped one pixel at a time along
// their major axis; depth is 1/z-interpolated. Only the steps whose brush can reach the band's rows
// are visited.
void draw_strands(const StrandSet &strands, const Projector &proj, const Lights &lights, const StrandLayer &layer,
                  Raster &r_raster) {
  const int size = r_raster.size;
  const int y_begin = r_raster.y_begin, y_end = r_raster.y_end();
  const int brush = layer.brush;
  std::vector<float> &depth = layer.overlay ? r_raster.overlay_depth : r_raster.depth;
  for (size_t s = 0; s < strands.strand_count(); ++s) {
    if (layer.on_top && (layer.on_top[s] != 0) != (layer.top != 0)) continue;
    const auto points = strands.points(s);
    if (points.size() < 2) continue;
    const Eigen::Vector3f &base = layer.colors ? layer.colors[s] : layer.color;
    const float segment_count = float(points.size() - 1);
    for (size_t i = 0; i + 1 < points.size(); ++i) {
      const Eigen::Vector3f d = points[i + 1] - points[i];
      if (d.squaredNorm() == 0.0f) continue;
      const Eigen::Vector3f a = proj.project(points[i]);
      const Eigen::Vector3f b = proj.project(points[i + 1]);
      if (a.z() <= proj.near || b.z() <= proj.near) continue;
      const float dx = b.x() - a.x(), dy = b.y() - a.y();
      const int steps = std::max(1, int(std::ceil(std::max(std::abs(dx), std::abs(dy)))));
      // Step k covers rows floor(y_k) - brush / 2 + [0, brush) with y_k = a.y + (k / steps) dy: it
      // reaches the band when y_k lies in [lo, hi) below; one row and one step of margin absorb rounding.
      const double lo = double(y_begin) - brush + brush / 2 - 1.0;
      const double hi = double(y_end) + brush / 2 + 1.0;
      int k_first = 0, k_last = steps;
      if (dy == 0.0f) {
        if (a.y() < lo || a.y() >= hi) continue;
      } else {
        const double t0 = (lo - a.y()) / dy, t1 = (hi - a.y()) / dy;
        const double k0 = std::floor(std::min(t0, t1) * steps) - 1.0;
        const double k1 = std::ceil(std::max(t0, t1) * steps) + 1.0;
        if (k1 < 0.0 || k0 > double(steps)) continue;
        k_first = int(std::max(k0, 0.0));
        k_last = int(std::min(k1, double(steps)));
      }
      const Eigen::Vector3f tangent = d.normalized();
      const Eigen::Vector3f mid = 0.5f * (points[i] + points[i + 1]);
      const Eigen::Vector3f view = (proj.eye - mid).normalized();
      // Hair near the scalp sits under other hair: darken the first third of every strand.
      const float along = (float(i) + 0.5f) / segment_count;
      const float occlusion = layer.root_shadow ? 0.3f + 0.7f * std::min(1.0f, along / 0.35f) : 1.0f;
      const Eigen::Vector3f c = shade_hair(tangent, view, lights, base, occlusion);
      const float inv_za = 1.0f / a.z(), inv_zb = 1.0f / b.z();
      for (int k = k_first; k <= k_last; ++k) {
        const float t = float(k) / float(steps);
        const int x = int(std::floor(a.x() + t * dx)) - brush / 2;
        const int y = int(std::floor(a.y() + t * dy)) - brush / 2;
        const float z = 1.0f / (inv_za + t * (inv_zb - inv_za));
        for (int by = y; by < y + brush; ++by) {
          if (by < y_begin || by >= y_end) continue;
          for (int bx = x; bx < x + brush; ++bx) {
            if (bx < 0 || bx >= size) continue;
            const size_t pixel = r_raster.index(bx, by);
            if (!(z < depth[pixel])) continue;
            depth[pixel] = z;
            r_raster.color[pixel] = c;
          }
        }
      }
    }
  }
}

// The sRGB transfer function, as browsers apply it to the viewer's colours.
uint8_t encode(float linear) {
  const float c = std::clamp(linear, 0.0f, 1.0f);
  const float v = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return uint8_t(std::lround(v * 255.0f));
}

}  // namespace

CameraAngle parse_camera_angle(const std::string &text, const std::string &what) {
  const CameraAngle three_quarter;
  if (text == "front") return {0.0f, 0.0f};
  if (text == "right") return {90.0f, 0.0f};
  if (text == "back") return {180.0f, 0.0f};
  if (text == "left") return {-90.0f, 0.0f};
  if (text == "top") return {0.0f, 90.0f};
  if (text == "three-quarter") return three_quarter;
  // "AZ" or "AZ,EL": finite numbers, the elevation in [-90, 90].
  const auto number = [&](const std::string &part, double &r_value) {
    char *end = nullptr;
    r_value = std::strtod(part.c_str(), &end);
    return !part.empty() && *end == '\0' && std::isfinite(r_value) && std::abs(r_value) <= 1e6;
  };
  const size_t comma = text.find(',');
  double azimuth = 0.0, elevation = three_quarter.elevation_degrees;
  const bool parsed = number(text.substr(0, comma), azimuth) &&
                      (comma == std::string::npos || number(text.substr(comma + 1), elevation));
  if (!parsed || std::abs(elevation) > 90.0)
    throw InputError(what + ": expected front, back, left, right, top, three-quarter, or an orbit angle in degrees "
                            "(\"AZ\" or \"AZ,EL\", EL in [-90, 90]), got \"" + text + "\"");
  return {float(azimuth), float(elevation)};
}

namespace {

// The unit view direction from the target to the eye, and the picture's up, for `angle`.
void camera_axes(const CameraAngle &angle, const Eigen::Vector3f &up, const Eigen::Vector3f &front,
                 Eigen::Vector3f &r_to_eye, Eigen::Vector3f &r_picture_up) {
  const Eigen::Vector3f up_n = up.normalized();
  Eigen::Vector3f front_n = front - front.dot(up_n) * up_n;
  if (front_n.squaredNorm() < 1e-12f) front_n = up_n.unitOrthogonal();
  front_n.normalize();
  const Eigen::Vector3f horizontal = Eigen::AngleAxisf(angle.azimuth_degrees * kPi / 180.0f, up_n) * front_n;
  const float elevation = angle.elevation_degrees * kPi / 180.0f;
  r_to_eye = (std::cos(elevation) * horizontal + std::sin(elevation) * up_n).normalized();
  r_picture_up = (-std::sin(elevation) * horizontal + std::cos(elevation) * up_n).normalized();
}

// The distance from the centre of `bounds` at which a camera looking along -to_eye sees every
// corner of `bounds` with a 6% margin (at least the bounding sphere's radius).
float fitted_distance(const Eigen::AlignedBox3f &bounds, const Eigen::Vector3f &to_eye, const Eigen::Vector3f &picture_up,
                      float fov_y_degrees) {
  // Start from the distance at which the bounding sphere fits, then move in as long as every corner
  // of the box still projects inside the frame with a 6% margin (the sphere leaves the box small).
  const Eigen::Vector3f target = bounds.center();
  const float radius = std::max(0.5f * bounds.diagonal().norm(), 1e-6f);
  const float half_fov = 0.5f * fov_y_degrees * kPi / 180.0f;
  const float limit = 0.94f * std::tan(half_fov);
  const Eigen::Vector3f forward = -to_eye;
  const Eigen::Vector3f right = forward.cross(picture_up).normalized();
  const Eigen::Vector3f up_view = right.cross(forward);
  auto fits = [&](float distance) {
    const Eigen::Vector3f eye = target + to_eye * distance;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3f d = bounds.corner(Eigen::AlignedBox3f::CornerType(corner)) - eye;
      const float z = d.dot(forward);
      if (z <= 0.0f || std::abs(d.dot(right)) > limit * z || std::abs(d.dot(up_view)) > limit * z) return false;
    }
    return true;
  };
  float far = radius / std::sin(half_fov) * 1.05f;
  float near = radius;  // the eye must stay outside the bounding sphere
  if (fits(near)) far = near;
  for (int i = 0; i < 40 && far - near > 1e-4f * far; ++i) {
    const float mid = 0.5f * (near + far);
    (fits(mid) ? far : near) = mid;
  }
  return far;
}

}  // namespace

PreviewCamera fit_camera(const Eigen::AlignedBox3f &bounds, const CameraAngle &angle, const Eigen::Vector3f &up,
                         const Eigen::Vector3f &front) {
  return turntable_cameras(bounds, 1, angle, up, front).front();
}

std::vector<PreviewCamera> turntable_cameras(const Eigen::AlignedBox3f &bounds, int count, const CameraAngle &start,
                                             const Eigen::Vector3f &up, const Eigen::Vector3f &front) {
  std::vector<PreviewCamera> cameras(size_t(std::max(count, 1)));
  std::vector<Eigen::Vector3f> to_eye(cameras.size());
  float distance = 0.0f;
  for (size_t i = 0; i < cameras.size(); ++i) {
    CameraAngle angle = start;
    angle.azimuth_degrees += 360.0f * float(i) / float(cameras.size());
    camera_axes(angle, up, front, to_eye[i], cameras[i].up);
    cameras[i].target = bounds.center();
    distance = std::max(distance, fitted_distance(bounds, to_eye[i], cameras[i].up, cameras[i].fov_y_degrees));
  }
  for (size_t i = 0; i < cameras.size(); ++i) cameras[i].eye = cameras[i].target + to_eye[i] * distance;
  return cameras;
}

Eigen::Vector3f plain_hair_color(const PreviewStyle &style, uint64_t id) {
  return style.hair_color * (0.7f + 0.6f * hash_to_unit(hash64(id)));
}

Eigen::AlignedBox3f scene_bounds(const Mesh &mesh, const StrandSet &strands) {
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f &p : mesh.positions) box.extend(p);
  for (const Eigen::Vector3f &p : strands.positions) box.extend(p);
  if (box.isEmpty()) box.extend(Eigen::Vector3f::Zero());
  return box;
}

Image render_preview(const PreviewCamera &camera, const Mesh &mesh, const StrandSet &strands, const StrandSet *guides,
                     const PreviewStyle &style, const StrandPaint &paint) {
  const size_t strand_count = strands.strand_count();
  if ((!paint.colors.empty() && paint.colors.size() != strand_count) ||
      (!paint.on_top.empty() && paint.on_top.size() != strand_count))
    throw InternalError("render_preview: the paint has " + std::to_string(paint.colors.size()) + " colours and " +
                        std::to_string(paint.on_top.size()) + " flags for " + std::to_string(strand_count) + " strands");
  const int ss = std::max(1, style.supersample);
  const int raster_size = style.size * ss;
  const Projector proj(camera, raster_size);
  const Lights lights(proj);
  std::vector<Eigen::Vector3f> screen(mesh.vertex_count());
  for (size_t v = 0; v < mesh.vertex_count(); ++v) screen[v] = proj.project(mesh.positions[v]);

  std::vector<Eigen::Vector3f> plain;
  if (paint.colors.empty()) {
    plain.resize(strand_count);
    for (size_t s = 0; s < strand_count; ++s) plain[s] = plain_hair_color(style, s < strands.ids.size() ? strands.ids[s] : s);
  }
  StrandLayer hair;
  hair.colors = paint.colors.empty() ? plain.data() : paint.colors.data();
  hair.on_top = paint.on_top.empty() ? nullptr : paint.on_top.data();
  hair.brush = std::max(1, style.strand_brush);
  StrandLayer hair_on_top = hair;
  hair_on_top.top = 1;
  hair_on_top.overlay = true;
  StrandLayer guide_layer;
  guide_layer.color = style.guide_color;
  guide_layer.root_shadow = false;
  guide_layer.overlay = true;
  guide_layer.brush = ss;

  Image image;
  image.width = image.height = style.size;
  image.rgb.resize(size_t(style.size) * style.size * 3);
  // The supersampled raster (20 bytes a sample, ss^2 samples a pixel: 12 GB at 8192 pixels) is
  // drawn in bands of whole image rows of at most kPreviewBandBytes each. Every sample lies in one
  // band and receives there the same writes in the same order as in a single pass, so the picture
  // does not depend on the banding.
  const size_t row_bytes = size_t(ss) * size_t(raster_size) * (sizeof(Eigen::Vector3f) + 2 * sizeof(float));
  const int band_rows = int(std::clamp<size_t>(kPreviewBandBytes / row_bytes, 1, size_t(style.size)));
  const float norm = 1.0f / float(ss * ss);
  for (int band_first = 0; band_first < style.size; band_first += band_rows) {
    const int rows = std::min(band_rows, style.size - band_first);
    Raster raster(raster_size, band_first * ss, rows * ss, style);
    draw_mesh(mesh, screen, proj, lights, style, paint.triangle_colors, raster);
    raster.begin_overlays();
    draw_strands(strands, proj, lights, hair, raster);
    if (hair.on_top) draw_strands(strands, proj, lights, hair_on_top, raster);
    if (guides) draw_strands(*guides, proj, lights, guide_layer, raster);
    for (int y = band_first; y < band_first + rows; ++y) {
      for (int x = 0; x < style.size; ++x) {
        Eigen::Vector3f sum = Eigen::Vector3f::Zero();
        for (int sy = 0; sy < ss; ++sy)
          for (int sx = 0; sx < ss; ++sx) sum += raster.color[raster.index(x * ss + sx, y * ss + sy)];
        sum *= norm;
        uint8_t *out = &image.rgb[(size_t(y) * style.size + x) * 3];
        for (int k = 0; k < 3; ++k) out[k] = encode(sum[k]);
      }
    }
  }
  return image;
}

Image tile_images(const std::vector<Image> &images, int columns) {
  if (images.empty() || columns < 1) throw InternalError("tile_images: no image or no column");
  const int cell_width = images.front().width, cell_height = images.front().height;
  for (const Image &image : images)
    if (image.width != cell_width || image.height != cell_height)
      throw InternalError("tile_images: the images differ in size");
  columns = std::min(columns, int(images.size()));
  const int rows = (int(images.size()) + columns - 1) / columns;
  Image sheet;
  sheet.width = cell_width * columns;
  sheet.height = cell_height * rows;
  sheet.rgb.resize(size_t(sheet.width) * size_t(sheet.height) * 3);
  const uint8_t *fill = images.front().rgb.data();
  for (size_t p = 0; p < sheet.rgb.size(); p += 3) std::copy(fill, fill + 3, &sheet.rgb[p]);
  for (size_t i = 0; i < images.size(); ++i) {
    const int x0 = int(i % size_t(columns)) * cell_width, y0 = int(i / size_t(columns)) * cell_height;
    for (int y = 0; y < cell_height; ++y)
      std::copy_n(&images[i].rgb[size_t(y) * cell_width * 3], size_t(cell_width) * 3,
                  &sheet.rgb[(size_t(y0 + y) * size_t(sheet.width) + size_t(x0)) * 3]);
  }
  return sheet;
}

void write_png(const std::string &path, const Image &image) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) throw InternalError("libpng: cannot create a write struct");
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    throw InternalError("libpng: cannot create an info struct");
  }
  // Encode to memory first, so a failure leaves no file; then write it atomically.
  std::vector<uint8_t> encoded;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw InternalError("libpng: encoding " + path + " failed");
  }
  png_set_write_fn(
      png, &encoded,
      [](png_structp p, png_bytep data, png_size_t length) {
        auto *buffer = static_cast<std::vector<uint8_t> *>(png_get_io_ptr(p));
        buffer->insert(buffer->end(), data, data + length);
      },
      nullptr);
  png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, const_cast<png_bytep>(&image.rgb[size_t(y) * image.width * 3]));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);

  io::AtomicFile file(path);
  file.write(encoded.data(), encoded.size());
  file.commit();
}

}  // namespace plume
