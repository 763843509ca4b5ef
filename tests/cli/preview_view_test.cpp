// The preview PNGs that must not mislead (skin shaded as skin, guides over the strands, camera
// choices, turntables, the checker's problems highlighted) and `plume view`'s refusals of bad
// input. The page itself is tested in a browser: tests/viewer.
#include <png.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <regex>

#include "cli/cli_fixtures.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

using namespace plume::cli_test;

namespace {

struct Picture {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  const uint8_t *at(int x, int y) const { return &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
};

Picture read_png(const std::string &path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  REQUIRE(png_image_begin_read_from_file(&image, path.c_str()) != 0);
  image.format = PNG_FORMAT_RGB;
  Picture picture;
  picture.width = int(image.width);
  picture.height = int(image.height);
  picture.rgb.resize(PNG_IMAGE_SIZE(image));
  REQUIRE(png_image_finish_read(&image, nullptr, picture.rgb.data(), 0, nullptr) != 0);
  return picture;
}

int difference(const uint8_t *a, const uint8_t *b) {
  return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]);
}

/// The fraction of pixels of the window [x0, x1) x [y0, y1) (fractions of the size) that are
/// alike (summed channel difference below 30) in `a` and `b`.
double alike_fraction(const Picture &a, const Picture &b, double x0, double y0, double x1, double y1) {
  REQUIRE(a.width == b.width);
  REQUIRE(a.height == b.height);
  int alike = 0, total = 0;
  for (int y = int(y0 * a.height); y < int(y1 * a.height); ++y)
    for (int x = int(x0 * a.width); x < int(x1 * a.width); ++x, ++total)
      if (difference(a.at(x, y), b.at(x, y)) < 30) ++alike;
  return double(alike) / double(std::max(total, 1));
}

template <typename Test>
int count_pixels(const Picture &picture, const Test &test) {
  int count = 0;
  for (int y = 0; y < picture.height; ++y)
    for (int x = 0; x < picture.width; ++x)
      if (test(picture.at(x, y))) ++count;
  return count;
}

bool guide_colored(const uint8_t *p) { return p[2] > 170 && p[1] > 140 && p[0] < 120; }
bool inside_colored(const uint8_t *p) { return p[0] > 180 && p[1] < 90 && p[2] < 90; }

RunResult run_ok(const std::string &args, const ScratchDir &scratch) {
  INFO("plume " << args);
  const RunResult run = run_plume(args, scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  return run;
}

/// Runs `args` and checks exit 2, a message holding `message`, and nothing written in `out`.
void require_refused(const std::string &args, const std::string &message, const ScratchDir &scratch,
                     const fs::path &out) {
  INFO("plume " << args);
  const RunResult run = run_plume_bounded(args, scratch);
  INFO(run.err);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find(message) != std::string::npos);
  CHECK(files_in(out).empty());
}

}  // namespace

TEST_CASE("a sparse groom's scalp is shaded as skin: seen from above, the head is mostly the bald head", "[cli]") {
  // 400 strands of 8 points cover a small part of the scalp: between them the skin must show, as
  // on the head with a single strand, not a cap painted in the hair's colour.
  ScratchDir scratch("preview_scalp");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const std::string common = " --frame 1 --camera top --size 160 --out ";
  run_ok("preview " + quoted(groom) + " --strands 1" + common + quoted(scratch / "bald.png"), scratch);
  run_ok("preview " + quoted(groom) + common + quoted(scratch / "sparse.png"), scratch);
  const double alike = alike_fraction(read_png(scratch / "bald.png"), read_png(scratch / "sparse.png"), 0.4, 0.4, 0.6, 0.6);
  INFO("pixels of the head's centre alike with and without hair: " << alike);
  CHECK(alike > 0.45);
}

TEST_CASE("guides are drawn over the strands: a dense groom hides almost none of them", "[cli]") {
  ScratchDir scratch("preview_guides");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const std::string common = " --frame 1 --guides --size 200 --out ";
  run_ok("preview " + quoted(groom) + " --strands 1" + common + quoted(scratch / "guides.png"), scratch);
  run_ok("preview " + quoted(groom) + " --strands 3000" + common + quoted(scratch / "dense.png"), scratch);
  run_ok("preview " + quoted(groom) + " --strands 3000 --frame 1 --size 200 --out " + quoted(scratch / "none.png"), scratch);
  const int alone = count_pixels(read_png(scratch / "guides.png"), guide_colored);
  const int over_hair = count_pixels(read_png(scratch / "dense.png"), guide_colored);
  const int without = count_pixels(read_png(scratch / "none.png"), guide_colored);
  INFO("guide-coloured pixels: guides alone " << alone << ", over 3000 strands " << over_hair << ", no guides " << without);
  CHECK(alone > 1000);
  CHECK(without < alone / 20);
  CHECK(over_hair > alone * 8 / 10);
}

TEST_CASE("camera names are orbit angles, and a turntable turns from the camera chosen", "[cli]") {
  ScratchDir scratch("preview_camera");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const auto render = [&](const std::string &options, const std::string &name) {
    run_ok("preview " + quoted(groom) + " --strands 200 --size 64 " + options + " --out " + quoted(scratch / name), scratch);
    return read_text(scratch / name);
  };
  // Names and angles give the same bytes.
  CHECK(render("", "default.png") == render("--camera three-quarter", "tq.png"));
  CHECK(render("--camera 35", "35.png") == render("--camera 35,10", "35_10.png"));
  CHECK(render("--camera three-quarter", "tq.png") == render("--camera 35", "35.png"));
  const std::vector<std::pair<std::string, std::string>> names = {
      {"front", "0,0"}, {"right", "90,0"}, {"back", "180,0"}, {"left", "-90,0"}, {"top", "0,90"}};
  std::vector<std::string> pictures;
  for (const auto &[name, angle] : names) {
    pictures.push_back(render("--camera " + name, name + ".png"));
    CHECK(pictures.back() == render("--camera " + angle, name + "_angle.png"));
  }
  for (size_t i = 0; i < pictures.size(); ++i)
    for (size_t j = i + 1; j < pictures.size(); ++j) CHECK(pictures[i] != pictures[j]);

  // A turntable of two from the right: the right and left views, each as drawn alone (the two
  // views are mirror images of the box, so they need the same distance).
  render("--camera right --turntable 2", "pair.png");
  const Picture pair = read_png(scratch / "pair.png");
  REQUIRE(pair.width == 128);
  REQUIRE(pair.height == 64);
  for (const auto &[name, cell] : {std::pair{std::string("right"), 0}, std::pair{std::string("left"), 1}}) {
    const Picture alone = read_png(scratch / (name + ".png"));
    int differing = 0;
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) differing += difference(alone.at(x, y), pair.at(64 * cell + x, y)) != 0;
    INFO(name << " view against the turntable's cell " << cell);
    CHECK(differing == 0);
  }
}

TEST_CASE("a turntable is one strip up to 4 views, else a sheet about twice as wide as tall", "[cli]") {
  ScratchDir scratch("preview_turntable");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const std::vector<std::tuple<std::string, int, int>> layouts = {
      {"--turntable 3", 3, 1}, {"--turntable 4", 4, 1}, {"--turntable 5", 3, 2},
      {"--turntable 8", 4, 2}, {"--turntable 3 --columns 1", 1, 3}, {"--turntable 1", 1, 1}};
  for (const auto &[options, columns, rows] : layouts) {
    run_ok("preview " + quoted(groom) + " --strands 100 --size 48 " + options + " --out " + quoted(scratch / "t.png"), scratch);
    const Picture sheet = read_png(scratch / "t.png");
    INFO(options);
    CHECK(sheet.width == 48 * columns);
    CHECK(sheet.height == 48 * rows);
  }
  // The views of an 8-view turntable differ from one another.
  run_ok("preview " + quoted(groom) + " --strands 100 --size 48 --turntable 8 --out " + quoted(scratch / "t8.png"), scratch);
  const Picture sheet = read_png(scratch / "t8.png");
  for (int a = 0; a < 8; ++a)
    for (int b = a + 1; b < 8; ++b) {
      int differing = 0;
      for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 48; ++x)
          differing += difference(sheet.at(48 * (a % 4) + x, 48 * (a / 4) + y), sheet.at(48 * (b % 4) + x, 48 * (b / 4) + y)) > 30;
      INFO("views " << a << " and " << b);
      CHECK(differing > 48 * 48 / 50);
    }
}

TEST_CASE("previews highlight what plume check reports, with its counts", "[cli]") {
  // Linear blending (a baseline) leaves crossing pairs; every method keeps points out of the skin,
  // so a skin margin of 0.5 (points nearer the skin than that count as inside) makes some.
  ScratchDir scratch("preview_problems");
  const std::string linear = write_sintel_groom(scratch, "linear", "interpolation: {method: linear, k: 4}\n");
  const std::string clean = write_sintel_groom(scratch, "clean", "");
  // Frame 1 is the rest pose: the emitter OBJ is the skin the strands stand on. Both derive the
  // crossing tolerance from the strands (1e-3 of their median segment).
  RunResult preview = run_ok("preview " + quoted(linear) + " --frame 1 --size 200 --color problems --margin 0.5 --out " +
                                 quoted(scratch / "linear.png"),
                             scratch);
  run_ok("regrow " + quoted(linear) + " --frames 1 --out " + quoted(scratch / "linear.####.hair"), scratch);
  const RunResult check = run_ok("check " + quoted(scratch / "linear.0001.hair") + " --margin 0.5 --mesh " + quoted(sintel_dir() + "/sintel.obj"),
                                 scratch);
  std::smatch found;
  REQUIRE(std::regex_search(check.out, found, std::regex(R"(points inside the skin \(margin 0.5\): (\d+))")));
  const std::string inside = found[1];
  REQUIRE(std::regex_search(check.out, found,
                            std::regex(R"(crossing strand pairs (\(tolerance [0-9.e+-]+\)): (\d+) transversal \(angle above 10 degrees\), (\d+) touching)")));
  const std::string tolerance = found[1], transversal = found[2], touching = found[3];
  INFO(preview.out << check.out);
  CHECK(std::stoi(inside) > 0);
  CHECK(std::stoi(transversal) > 0);
  CHECK(preview.out.find("frame 1: " + inside + " points inside the skin (margin 0.5)") != std::string::npos);
  CHECK(preview.out.find("crossing strand pairs " + tolerance + ": " + transversal + " transversal, " + touching +
                         " touching; drawn: " + transversal + " transversal, " + touching + " touching") != std::string::npos);
  const int red = count_pixels(read_png(scratch / "linear.png"), inside_colored);
  CHECK(red > 100);

  // The plain colours have no red; a clean groom's problem picture neither.
  run_ok("preview " + quoted(linear) + " --frame 1 --size 200 --out " + quoted(scratch / "plain.png"), scratch);
  CHECK(count_pixels(read_png(scratch / "plain.png"), inside_colored) == 0);
  preview = run_ok("preview " + quoted(clean) + " --frame 1 --size 200 --color problems --out " + quoted(scratch / "clean.png"), scratch);
  CHECK(preview.out.find("frame 1: 0 points inside the skin") != std::string::npos);
  CHECK(count_pixels(read_png(scratch / "clean.png"), inside_colored) == 0);
}

TEST_CASE("a groom with effects has its crossings judged before them, as plume check --groom does", "[cli]") {
  ScratchDir scratch("preview_effects");
  const std::string groom = write_sintel_groom(
      scratch, "clumps", "effects:\n  - {type: clump, seed: 1, centers: poisson, radius: 1.2, amount: 0.8}\n");
  const RunResult preview = run_ok("preview " + quoted(groom) + " --frame 1 --size 64 --color problems --out " +
                                       quoted(scratch / "p.png"),
                                   scratch);
  run_ok("regrow " + quoted(groom) + " --frames 1 --out " + quoted(scratch / "h.####.usda"), scratch);
  const RunResult check = run_ok("check " + quoted(scratch / "h.0001.usda") + " --groom " + quoted(groom), scratch);
  std::smatch found;
  REQUIRE(std::regex_search(check.out, found,
                            std::regex(R"(crossing strand pairs before effects (\(tolerance [0-9.e+-]+\)): (\d+) transversal \(angle above 10 degrees\), (\d+) touching)")));
  INFO(preview.out << check.out);
  CHECK(preview.out.find("crossing strand pairs before effects " + std::string(found[1]) + ": " + std::string(found[2]) +
                         " transversal, " + std::string(found[3]) + " touching") != std::string::npos);
}

TEST_CASE("preview and view refuse bad camera, colour and page options with exit 2 and no output", "[cli]") {
  ScratchDir scratch("view_refusals");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const fs::path out = scratch.path / "out";
  const std::string o = out.string();
  const std::string preview = "preview " + quoted(groom) + " --strands 50 --size 64 --out " + quoted(o + "/p.png");
  for (const std::string camera : {"sideways", "10,91", "nan", "1e400", "10,", ",10", "inf,0"})
    require_refused(preview + " --camera " + quoted(camera), "--camera", scratch, out);
  require_refused(preview + " --color rainbow", "--color", scratch, out);
  require_refused(preview + " --turntable 145", "--turntable", scratch, out);
  require_refused(preview + " --turntable 0", "--turntable", scratch, out);
  require_refused("preview " + quoted(groom) + " --size 8192 --turntable 2 --out " + quoted(o + "/p.png"), "--turntable 2",
                  scratch, out);
  require_refused(preview + " --color problems --tolerance nan", "--tolerance", scratch, out);
  // A tolerance beyond the checker's budget (near the strands' spacing) is refused as plume check refuses it.
  const std::string dense = "preview " + quoted(groom) + " --strands 2000 --size 64 --out " + quoted(o + "/p.png");
  require_refused(dense + " --color problems --tolerance 50", "--tolerance 50", scratch, out);

  const std::string view = "view " + quoted(groom) + " --strands 50 --frames 1-3";
  require_refused(view + " --out " + quoted(o + "/v.png"), "--out: expected a file ending in .html", scratch, out);
  require_refused(view + " --out " + quoted(o + "/v.####.html"), "--out: one page holds every frame", scratch, out);
  require_refused(view + " --out " + quoted(o + "/v.%04d.html"), "--out: one page holds every frame", scratch, out);
  require_refused(view + " --max-points 1000 --out " + quoted(o + "/v.html"), "--max-points 1000", scratch, out);
  require_refused(view + " --max-points 0 --out " + quoted(o + "/v.html"), "--max-points", scratch, out);
  require_refused(view + " --max-points 99999999999 --out " + quoted(o + "/v.html"), "--max-points", scratch, out);
  require_refused(view + " --max-points 32000001 --out " + quoted(o + "/v.html"), "--max-points", scratch, out);
  require_refused(view + " --tolerance -1 --out " + quoted(o + "/v.html"), "--tolerance", scratch, out);
  require_refused("view " + quoted(groom) + " --strands 2000 --frames 1 --tolerance 50 --out " + quoted(o + "/v.html"),
                  "--tolerance 50", scratch, out);
  require_refused(view + " --frames 1-3:0 --out " + quoted(o + "/v.html"), "--frames", scratch, out);
  require_refused("view " + quoted(scratch / "missing.groom.yaml") + " --out " + quoted(o + "/v.html"), "missing.groom.yaml",
                  scratch, out);
  require_refused("view " + quoted(groom) + " --out " + quoted(groom), "--out", scratch, out);
  fs::create_directories(out / "dir.html");
  const RunResult directory = run_plume_bounded(view + " --out " + quoted(o + "/dir.html"), scratch);
  CHECK(directory.exit_code == 2);
  CHECK(directory.err.find("is an existing directory") != std::string::npos);
  fs::remove(out / "dir.html");
}

TEST_CASE("view refuses bad strand files, meshes and options with exit 2 and no output", "[cli]") {
  ScratchDir scratch("view_files");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const fs::path out = scratch.path / "out";
  const std::string o = out.string();
  const std::string mesh = sintel_dir() + "/sintel.obj";
  run_ok("regrow " + quoted(groom) + " --frames 1-3 --strands 30 --out " + quoted(scratch / "h.####.hair"), scratch);
  run_ok("regrow " + quoted(groom) + " --frames 1 --strands 40 --out " + quoted(scratch / "other.####.hair"), scratch);
  const std::string page = " --out " + quoted(o + "/v.html");
  const std::string pattern = quoted(scratch / "h.####.hair");
  require_refused("view " + pattern + " --frames 1-3" + page, "--mesh: expected the skin", scratch, out);
  require_refused("view " + pattern + " --mesh " + quoted(mesh) + page, "--frames", scratch, out);
  require_refused("view " + quoted(scratch / "h.0001.hair") + " --frames 1-2 --mesh " + quoted(mesh) + page,
                  "a range needs a pattern", scratch, out);
  require_refused("view " + pattern + " --frames 1-3 --mesh " + quoted(scratch / "h.0001.hair") + page,
                  "--mesh: expected an .obj", scratch, out);
  require_refused("view " + pattern + " --frames 1-4 --mesh " + quoted(mesh) + page, "h.0004.hair", scratch, out);
  require_refused("view " + pattern + " --frames 1-3 --strands 10 --mesh " + quoted(mesh) + page, "--strands", scratch, out);
  require_refused("view " + quoted(groom) + " --mesh " + quoted(mesh) + page, "--mesh: a groom names its emitter",
                  scratch, out);
  require_refused("view " + quoted(scratch / "h.0001.txt") + " --mesh " + quoted(mesh) + page,
                  "expected a groom (.yaml) or strand files", scratch, out);
  // A frame whose file holds other strands than the first frame's.
  fs::copy_file(scratch / "other.0001.hair", scratch / "h.0002.hair", fs::copy_options::overwrite_existing);
  require_refused("view " + pattern + " --frames 1-3 --mesh " + quoted(mesh) + page, "h.0002.hair", scratch, out);
  // A mesh pattern whose frame is missing.
  require_refused("view " + quoted(scratch / "h.0001.hair") + " --frames 7 --mesh " + quoted(scratch / "skin.####.obj") + page,
                  "skin.0007.obj", scratch, out);
}

TEST_CASE("a view page is written whole, in one file, and names the groom", "[cli]") {
  ScratchDir scratch("view_page");
  const std::string groom = write_sintel_groom(scratch, "g", "name: little_head\n");
  const fs::path out = scratch.path / "out";
  run_ok("view " + quoted(groom) + " --strands 50 --frames 1-2 --out " + quoted(out.string() + "/v.html"), scratch);
  CHECK(files_in(out) == std::vector<std::string>{(out / "v.html").string()});
  const std::string page = read_text((out / "v.html").string());
  CHECK(page.rfind("<!DOCTYPE html>", 0) == 0);
  CHECK(page.find("<title>little_head</title>") != std::string::npos);
  CHECK(page.find("\"total\":50") != std::string::npos);
  CHECK(page.find("\"frames\":[1,2]") != std::string::npos);
  CHECK(page.size() > 100000);  // the viewer's script and three.js are inside
  CHECK(page.find("</html>\n") == page.size() - 8);
}

TEST_CASE("a groom modelled at another scale previews and is checked the same: no absolute unit", "[cli]") {
  // Sintel's head and guides scaled by 100 and by 0.01 (every length of the groom file too): the
  // camera, the lights, the strand brush and the checker's tolerance follow the scale, so the
  // picture is the same up to rounding and the checker finds the same problems.
  ScratchDir scratch("preview_scale");
  const plume::Mesh head = plume::io::read_obj_mesh(sintel_dir() + "/sintel.obj");
  const plume::StrandSet guides = plume::io::read_strands(sintel_dir() + "/sintel_guides.hair");
  const auto write_groom = [&](const std::string &name, float scale) {
    std::ofstream obj(scratch / (name + ".obj"));
    obj.precision(9);
    for (const Eigen::Vector3f &p : head.positions) obj << "v " << scale * p.x() << ' ' << scale * p.y() << ' ' << scale * p.z() << '\n';
    for (const Eigen::Vector3i &t : head.triangles) obj << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    obj.close();
    plume::StrandSet scaled = guides;
    for (Eigen::Vector3f &p : scaled.positions) p *= scale;
    scaled.widths.clear();
    plume::io::write_strands(scratch / (name + "_guides.hair"), scaled);
    std::ofstream groom(scratch / (name + ".groom.yaml"));
    groom << "plume: 1\nemitter: {mesh: " << name << ".obj}\nguides: {file: " << name << "_guides.hair}\n"
          << "roots: {count: 600, near_guides: " << 2.0f * scale << ", seed: 3}\nstrands: {points: 8}\n"
          << "interpolation: {method: linear, k: 4}\n";
    return scratch / (name + ".groom.yaml");
  };
  const auto preview = [&](const std::string &groom, const std::string &png) {
    return run_ok("preview " + quoted(groom) + " --size 160 --color problems --out " + quoted(scratch / png), scratch).out;
  };
  const std::string unit = preview(write_groom("unit", 1.0f), "unit.png");
  const Picture reference = read_png(scratch / "unit.png");
  // The counts (the first line: the summary after it names files and times), without the
  // tolerance (which scales).
  const auto counts = [](const std::string &text) {
    return std::regex_replace(text.substr(0, text.find('\n')), std::regex(R"(\(tolerance [^)]*\))"), "");
  };
  for (const float scale : {100.0f, 0.01f}) {
    const std::string name = scale > 1.0f ? "large" : "small";
    const std::string out = preview(write_groom(name, scale), name + ".png");
    INFO("scale " << scale << "\n" << unit << out);
    CHECK(counts(out) == counts(unit));
    const double alike = alike_fraction(reference, read_png(scratch / (name + ".png")), 0.0, 0.0, 1.0, 1.0);
    CHECK(alike > 0.99);
  }
}

