// The feather gallery (docs/gallery/*.png) and the README's bird (docs/bird.png) stay true: rendered
// again by grooms/gallery/make_gallery.sh, each picture is the one kept in docs/. And the preview
// of a feather groom takes its camera and turntable options as a hair groom's does.
#include <png.h>

#include <catch2/catch.hpp>
#include <cstdlib>

#include "cli/cli_fixtures.h"

using namespace plume::cli_test;

namespace {

struct Rgb {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;
};

Rgb read_rgb(const std::string &path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  INFO(path);
  REQUIRE(png_image_begin_read_from_file(&image, path.c_str()) != 0);
  image.format = PNG_FORMAT_RGB;
  Rgb rgb;
  rgb.width = int(image.width);
  rgb.height = int(image.height);
  rgb.pixels.resize(PNG_IMAGE_SIZE(image));
  REQUIRE(png_image_finish_read(&image, nullptr, rgb.pixels.data(), 0, nullptr) != 0);
  return rgb;
}

/// The fraction of pixels of `a` and `b` (the same size) whose channels differ by more than 2 of 255.
double differing_fraction(const Rgb &a, const Rgb &b) {
  REQUIRE(a.width == b.width);
  REQUIRE(a.height == b.height);
  size_t differing = 0;
  for (size_t p = 0; p < a.pixels.size(); p += 3)
    for (size_t c = 0; c < 3; ++c)
      if (std::abs(int(a.pixels[p + c]) - int(b.pixels[p + c])) > 2) {
        ++differing;
        break;
      }
  return double(differing) / double(std::max<size_t>(a.pixels.size() / 3, 1));
}

const std::string kGallery = std::string(PLUME_SOURCE_DIR) + "/grooms/gallery/";

}  // namespace

TEST_CASE("the feather gallery and the README's bird are what plume draws today", "[feathers][cli]") {
  ScratchDir scratch("gallery");
  const RunResult run = run_plume_command("sh " + quoted(kGallery + "make_gallery.sh") + " " + quoted(PLUME_BINARY) +
                                              " " + quoted(scratch.path.string()),
                                          scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  const std::string docs = std::string(PLUME_SOURCE_DIR) + "/docs/";
  for (const std::string name : {"gallery/contour.png", "gallery/down.png", "gallery/flight.png", "gallery/semi_plume.png",
                                 "gallery/semi_plume_below.png", "gallery/growth.png", "bird.png"}) {
    INFO(name << ": render the pictures again with grooms/gallery/make_gallery.sh if the change is meant");
    CHECK(differing_fraction(read_rgb(scratch / name), read_rgb(docs + name)) <= 0.001);
  }
}

TEST_CASE("a feather groom's preview takes --camera and --turntable, and refuses colours it cannot draw",
          "[feathers][cli]") {
  ScratchDir scratch("feather_camera");
  const std::string groom = quoted(kGallery + "contour.groom.yaml");
  const auto render = [&](const std::string &options, const std::string &name) {
    const RunResult run = run_plume("preview " + groom + " --size 64 " + options + " --out " + quoted(scratch / name), scratch);
    INFO(run.err);
    REQUIRE(run.exit_code == 0);
    return read_rgb(scratch / name);
  };
  const Rgb top = render("--camera top", "top.png");
  const Rgb side = render("--camera right", "right.png");
  const Rgb three_quarter = render("", "default.png");
  CHECK(differing_fraction(top, side) > 0.02);
  CHECK(differing_fraction(top, three_quarter) > 0.02);
  CHECK(differing_fraction(render("--camera 0,90", "angle.png"), top) == 0.0);
  // A turntable of two from the right: the right view, then the left.
  const Rgb pair = render("--camera right --turntable 2", "pair.png");
  REQUIRE(pair.width == 128);
  REQUIRE(pair.height == 64);
  Rgb first = side;
  for (int y = 0; y < 64; ++y)
    std::copy_n(pair.pixels.begin() + (size_t(y) * 128) * 3, 64 * 3, first.pixels.begin() + size_t(y) * 64 * 3);
  CHECK(differing_fraction(first, side) == 0.0);

  const RunResult colored = run_plume("preview " + groom + " --color guide --out " + quoted(scratch / "c.png"), scratch);
  CHECK(colored.exit_code == 2);
  CHECK(colored.err.find("--color guide") != std::string::npos);
  CHECK(!fs::exists(scratch / "c.png"));
}
