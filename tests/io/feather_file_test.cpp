// The feathers section of a groom file: every key reaches FeatherDesc, defaults scale with the
// feather, template files are read, and broken templates get file:line:column messages.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "io/feather_file.h"
#include "io/groom_file.h"
#include "io/scratch_dir.h"

namespace fs = std::filesystem;
using namespace plume;

namespace {

const fs::path data_dir = fs::path(PLUME_TEST_DATA);

std::string error_of(const std::string &path) {
  try {
    io::read_groom_file(path);
  } catch (const InputError &e) {
    return e.what();
  }
  FAIL("reading " << path << " threw no InputError");
  return "";
}

/// A broken fixture of tests/data/bad/ fails with "file:line:col: key.path: " and then `expected`.
void check_bad(const std::string &name, const std::string &line_col, const std::string &key_path,
               const std::string &expected, const std::string &file = "") {
  const std::string path = (data_dir / "bad" / name).string();
  const std::string message = error_of(path);
  const std::string named = file.empty() ? path : (data_dir / "bad" / file).string();
  INFO(message);
  CHECK(message.rfind(named + ":" + line_col + ": " + key_path + ": ", 0) == 0);
  CHECK(message.find(expected) != std::string::npos);
}

}  // namespace

TEST_CASE("every key of the feathers section reaches FeatherDesc", "[io][feathers]") {
  const GroomDesc groom = io::read_groom_file((data_dir / "feathers" / "valid.groom.yaml").string());
  const FeatherDesc &f = groom.feathers;
  REQUIRE(f.enabled);
  REQUIRE(f.templates.size() == 2);
  const FeatherTemplate &contour = f.templates[0];
  CHECK(contour.name == "contour");
  CHECK(contour.calamus_length == 0.05f);
  CHECK(contour.calamus_width_ratio == 0.7f);
  CHECK(contour.rachis_length == 0.6f);
  CHECK(contour.rachis_width == 0.012f);
  CHECK(contour.curvature_side == 0.02f);
  CHECK(contour.curvature_front == 0.06f);
  CHECK(contour.spacing_base == 0.02f);
  CHECK(contour.spacing_tip == 0.015f);
  CHECK(contour.barb_width == 0.001f);
  CHECK(contour.right.angle_base == 60.0f);
  CHECK(contour.right.angle_tip == 30.0f);
  CHECK(contour.right.silhouette.t.size() == 4);
  CHECK(contour.right.key_barbs.size() == 2);
  CHECK(contour.right.key_barbs[1].plumulaceous == 0.2f);
  CHECK(contour.right.key_barbs[0].points.size() == 4);
  // The left vane overrides angles and length; it keeps the shared key barbs.
  CHECK(contour.left.angle_base == 40.0f);
  CHECK(contour.left.barb_length == 0.08f);
  CHECK(contour.left.silhouette.t.empty());
  CHECK(contour.left.key_barbs.size() == 2);
  CHECK(contour.afterfeather == 0.3f);
  CHECK(contour.loc.line == 8);

  // From the template file, with defaults relative to the rachis length.
  const FeatherTemplate &down = f.templates[1];
  CHECK(down.name == "down");
  CHECK(down.loc.file == (data_dir / "feathers" / "templates.yaml").lexically_normal().string());
  CHECK(down.calamus_length == Approx(0.04f));
  CHECK(down.rachis_width == Approx(0.008f));
  CHECK(down.barb_width == Approx(0.0008f));
  REQUIRE(f.template_files.size() == 1);

  REQUIRE(f.key_feathers.size() == 2);
  CHECK(f.key_feathers[0].template_index == 0);
  CHECK(f.key_feathers[0].groups == std::vector<std::string>{"scalp"});
  CHECK(f.key_feathers[0].radius == 0.2f);
  CHECK(f.key_feathers[0].stage == 0.9f);
  CHECK(f.key_feathers[0].layer_given);
  CHECK(f.key_feathers[0].layer == 2.0f);
  CHECK_FALSE(f.key_feathers[1].layer_given);
  CHECK(f.key_feathers[1].layer == 0.0f);
  CHECK(f.key_feathers[1].template_index == 1);
  CHECK(f.key_feathers[1].point == Eigen::Vector3f(0.5f, 0.0f, 0.5f));
  CHECK(f.follicles.count == 20);
  CHECK(f.follicles.groups.size() == 2);
  CHECK(f.follicles.seed == 3);
  CHECK(f.guides_per_feather == 2);
  CHECK(f.falloff == 1.5f);
  CHECK(f.variation.length == 0.1f);
  CHECK(f.variation.direction == 5.0f);
  CHECK(f.variation.lift == 3.0f);
  CHECK(f.variation.barb_angle == 4.0f);
  CHECK(f.variation.stage == 0.1f);
  CHECK(f.variation.seed == 9);
  CHECK(f.detail.rachis_points == 12);
  CHECK(f.detail.barb_points == 6);
  CHECK(f.detail.vane_rows == 10);
  CHECK(f.detail.vane_columns == 3);
  CHECK(f.detail.uv == FeatherDetail::Uv::barb);
  CHECK(f.lift);
  CHECK(f.clearance == 0.03f);
  CHECK(f.layers);
  CHECK(f.layer_offset == 0.01f);
  CHECK(f.layer_map_path == (data_dir / "feathers" / "layer_map.txt").lexically_normal().string());
  CHECK(f.layer_front == std::vector<std::string>{"face"});
  CHECK(f.layer_rear == std::vector<std::string>{"scalp"});
  CHECK(f.layer_rear_loc.line == 29);
  CHECK(groom.output.vanes_pattern.ends_with("out/vanes.####.obj"));
  // Feather stems are stiffer than hair by default.
  CHECK(groom.dynamics.stiffness.at(0.0f) == 10.0f);
  CHECK(io::describe_groom(groom).find("feathers: 2 templates (contour, down)") != std::string::npos);
  CHECK(io::describe_groom(groom).find("layers: on, offset 0.01, order: the groom's (front face; rear scalp; key "
                                       "feathers' layers; map " +
                                       f.layer_map_path + "), then coverage at rest\n") != std::string::npos);
}

TEST_CASE("the feathers example of docs/groom-format.md is a valid groom", "[io][feathers]") {
  std::ifstream in(fs::path(PLUME_SOURCE_DIR) / "docs" / "groom-format.md");
  REQUIRE(in);
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t section = doc.find("## Feathers");
  REQUIRE(section != std::string::npos);
  const size_t begin = doc.find("```yaml\n", section);
  const size_t end = doc.find("```", begin + 8);
  REQUIRE(end != std::string::npos);
  // The files the example reads must exist; their content is not the groom reader's business.
  const fs::path folder = fs::temp_directory_path() / ("plume_feather_doc_" + std::to_string(::getpid()));
  fs::create_directories(folder / "anim");
  for (const char *name : {"bird.obj", "stems.hair", "density.txt"}) std::ofstream(folder / name) << "\n";
  std::ofstream(folder / "bird.feathers.yaml") << "templates:\n  down: {rachis: {length: 1}}\n";
  std::ofstream(folder / "example.groom.yaml") << doc.substr(begin + 8, end - begin - 8);
  const GroomDesc g = io::read_groom_file((folder / "example.groom.yaml").string());
  CHECK(g.feathers.enabled);
  CHECK(g.feathers.templates.size() == 2);
  CHECK(g.feathers.key_feathers.size() == 2);
  CHECK(g.feathers.follicles.count == 5000);
  CHECK(g.output.vanes_pattern.ends_with("vanes.####.obj"));
  fs::remove_all(folder);
}

TEST_CASE("bad templates give file:line:column errors naming the key", "[io][feathers]") {
  check_bad("feather_negative_length.groom.yaml", "8:24", "feathers.templates.contour.rachis.length",
            "expected a number > 0, got \"-3\"");
  check_bad("feather_unsorted_key_barbs.groom.yaml", "12:24", "feathers.templates.contour.barbs.key_barbs[1].position",
            "expected a position in [0.6, 1] (key barbs sorted from base to tip), got \"0.2\"");
  check_bad("feather_empty_silhouette.groom.yaml", "10:29", "feathers.templates.contour.barbs.right.silhouette",
            "expected at least one [t, length] point, got an empty list");
  check_bad("feather_unknown_template.groom.yaml", "8:29", "feathers.key_feathers[0].template",
            "expected a template name (contour), got \"flight\"");
  check_bad("feather_with_roots.groom.yaml", "5:8", "roots", "not allowed in a feather groom");
  check_bad("feather_too_many_barbs.groom.yaml", "9:24", "feathers.templates.contour.barbs.spacing",
            "expected at most 10000 barbs per vane over the rachis length 3, got more");
}

TEST_CASE("bad layer orders give file:line:column errors naming the key", "[io][feathers]") {
  const std::string valid = (data_dir / "feathers" / "valid.groom.yaml").string();
  std::string text;
  {
    std::ifstream in(valid);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  // The valid groom's relative paths made absolute, so that an edited copy reads from a scratch folder.
  for (const std::string name : {"../groom_file/", "../groom_file/", "templates.yaml", "layer_map.txt"}) {
    const size_t at = text.find(name);
    REQUIRE(at != std::string::npos);
    text.replace(at, name.size(), (data_dir / "feathers" / name).lexically_normal().string());
  }
  const size_t line = text.find("  layers: {enabled: true, offset: 0.01, map: ");
  REQUIRE(line != std::string::npos);
  const std::string layers = text.substr(line, text.find('\n', line) - line);
  const test::ScratchDir scratch("bad_layer_orders");
  const auto error_with = [&](const std::string &from, const std::string &to) {
    std::string edited = text;
    edited.replace(edited.find(from), from.size(), to);
    const std::string path = scratch.file("edited.groom.yaml");
    std::ofstream(path) << edited;
    const std::string message = error_of(path);
    return message.substr(message.find(".groom.yaml:") + 12);
  };
  CHECK(error_with(layers, "  layers: {enabled: true, front: [face, scalp], rear: [scalp]}") ==
        "29:55: feathers.layers.rear: the face group \"scalp\" is also in feathers.layers.front (a tract is either "
        "in front or at the rear)");
  CHECK(error_with(layers, "  layers: {front: []}") == "29:19: feathers.layers.front: expected at least one face group, got a list");
  CHECK(error_with(layers, "  layers: {map: missing.txt}").rfind("29:17: feathers.layers.map: expected an existing file, got \"missing.txt\"", 0) == 0);
  CHECK(error_with("stage: 0.9, layer: 2}", "stage: 0.9, layer: 2e9}") ==
        "22:76: feathers.key_feathers[0].layer: expected a number in [-1e+06, 1e+06], got \"2e9\"");
  CHECK(error_with("stage: 0.9, layer: 2}", "stage: 0.9, layer: .nan}").rfind("22:76: feathers.key_feathers[0].layer: expected a number", 0) == 0);
}

TEST_CASE("a template file's errors name that file and its line", "[io][feathers]") {
  const std::string message = error_of((data_dir / "feathers" / "bad_template_file.groom.yaml").string());
  const std::string file = (data_dir / "feathers" / "bad_templates.yaml").lexically_normal().string();
  INFO(message);
  CHECK(message.rfind(file + ":5:27: templates.down.barbs.angle.base: expected a number in [0, 180], got \"200\"", 0) == 0);
}

TEST_CASE("vanes are an output of feather grooms only", "[io][feathers]") {
  const fs::path folder = fs::temp_directory_path() / ("plume_feather_io_" + std::to_string(::getpid()));
  fs::create_directories(folder);
  const fs::path groom = folder / "hair.groom.yaml";
  {
    std::ofstream out(groom);
    out << "plume: 1\nemitter: {mesh: " << (data_dir / "groom_file" / "head.obj").string() << "}\nguides: {file: "
        << (data_dir / "groom_file" / "guides.obj").string() << "}\nroots: {count: 5}\noutput: {vanes: v.obj}\n";
  }
  const std::string message = error_of(groom.string());
  CHECK(message.find("output.vanes: not allowed without a feathers section") != std::string::npos);
  fs::remove_all(folder);
}
