// Groom files: every key of the format reaches GroomDesc, defaults are the documented ones, paths
// are resolved against the groom file, and every broken file gets a located, key-path message.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <regex>
#include <unistd.h>

#include "io/groom_file.h"

namespace fs = std::filesystem;
using plume::EffectDesc;
using plume::EffectType;
using plume::GroomDesc;
using plume::InputError;
using plume::io::read_groom_file;

namespace {

const fs::path data_dir = fs::path(PLUME_TEST_DATA);
const fs::path fixtures = data_dir / "groom_file";

std::string normal(const fs::path &p) { return fs::absolute(p).lexically_normal().string(); }

/// The message of the InputError that reading `path` throws (fails the test if none is thrown).
std::string error_of(const std::string &path) {
  try {
    read_groom_file(path);
  } catch (const InputError &e) {
    return e.what();
  }
  FAIL("reading " << path << " threw no InputError");
  return "";
}

/// A broken fixture of tests/data/bad/ must fail with "file:line:col: key.path: " and then `expected`.
void check_bad(const std::string &name, const std::string &line_col, const std::string &key_path,
               const std::string &expected) {
  const std::string path = (data_dir / "bad" / name).string();
  const std::string message = error_of(path);
  INFO(message);
  CHECK(message.rfind(path + ":" + line_col + ": " + key_path + ": ", 0) == 0);
  CHECK(message.find(expected) != std::string::npos);
}

/// Writes a groom into a fresh temporary folder (emitter and guides given by absolute paths) and
/// returns its path. `body` follows the required keys.
class TempGroom {
 public:
  TempGroom() {
    folder_ = fs::temp_directory_path() / ("plume_groom_file_test_" + std::to_string(::getpid()) + "_" +
                                           std::to_string(counter_++));
    fs::create_directories(folder_);
  }
  ~TempGroom() {
    std::error_code ec;
    fs::remove_all(folder_, ec);
  }
  const fs::path &folder() const { return folder_; }
  std::string write(const std::string &body, bool with_header = true) const {
    const fs::path path = folder_ / "test.groom.yaml";
    std::ofstream out(path);
    if (with_header)
      out << "plume: 1\n"
          << "emitter: {mesh: " << (fixtures / "head.obj").string() << "}\n"
          << "guides: {file: " << (fixtures / "guides.obj").string() << "}\n";
    out << body;
    return path.string();
  }

 private:
  fs::path folder_;
  static inline int counter_ = 0;
};


/// A groom body that must fail with "file:line:col: key_path: " and `expected` in the message.
struct KeyErrorCase {
  std::string body;
  std::string key_path;
  std::string expected;
};

/// Writes each case's body after the required keys and checks its message.
void check_key_errors(const TempGroom &t, const std::vector<KeyErrorCase> &cases) {
  for (const KeyErrorCase &c : cases) {
    const std::string path = t.write(c.body);
    const std::string message = error_of(path);
    INFO(c.body << " -> " << message);
    CHECK(std::regex_search(message, std::regex(R"(^[^:]+\.groom\.yaml:\d+:\d+: )")));
    CHECK(message.find(": " + c.key_path + ": ") != std::string::npos);
    CHECK(message.find(c.expected) != std::string::npos);
  }
}

}  // namespace

TEST_CASE("a full groom file sets every field of GroomDesc", "[io]") {
  const GroomDesc g = read_groom_file((fixtures / "full.groom.yaml").string());
  CHECK(g.source == normal(fixtures / "full.groom.yaml"));
  CHECK(g.name == "full test groom");

  CHECK(g.emitter_path == normal(fixtures / "head.obj"));
  CHECK(g.emitter_loc.line == 7);
  CHECK(g.emitter_loc.column == 9);
  CHECK(g.animation.kind == plume::EmitterAnimation::Kind::rigid);
  CHECK(g.animation.pivot.isApprox(Eigen::Vector3f(0.5f, 0, 0.5f)));
  REQUIRE(g.animation.keys.size() == 2);
  CHECK(g.animation.keys[0].frame == 1.0);
  CHECK(g.animation.keys[1].frame == 24.0);
  CHECK(g.animation.keys[1].translate.isApprox(Eigen::Vector3f(1, 2, 3)));
  CHECK(g.animation.keys[1].rotate_degrees.isApprox(Eigen::Vector3f(10, 20, 30)));
  CHECK(g.animation.keys[1].scale == 1.5f);
  CHECK(g.animation.loc.line == 9);

  CHECK(g.guides_path == normal(fixtures / "guides.obj"));
  CHECK(g.guides_loc.line == 15);

  CHECK(g.roots.source == plume::RootSettings::Source::scatter);
  CHECK(g.roots.count == 1500);
  CHECK(g.roots.density == 0.0);
  CHECK(g.roots.groups == std::vector<std::string>{"scalp"});
  CHECK(g.roots.near_guides == 0.1);
  CHECK(g.roots.seed == 7);

  CHECK(g.points_per_strand == 16);
  CHECK(g.width_root == 0.03f);
  CHECK(g.width_tip == 0.001f);

  const plume::InterpolationSettings &i = g.interpolation;
  CHECK(i.method == plume::InterpolationSettings::Method::fur);
  CHECK(i.k == 6);
  CHECK(i.radius == 2.5);
  CHECK(i.falloff == 3.0f);
  CHECK(i.skin_margin == 0.01f);
  CHECK_FALSE(i.separate);

  const plume::PartingSettings &p = g.partings;
  CHECK(p.zone_source == plume::PartingSettings::ZoneSource::face_groups);
  CHECK(p.zone_groups == std::vector<std::string>{"scalp", "face"});
  REQUIRE(p.lines.size() == 2);
  CHECK(p.lines[0].name == "side");
  REQUIRE(p.lines[0].points.size() == 3);
  CHECK(p.lines[0].points[2].isApprox(Eigen::Vector3f(0.9f, 0, 0.5f)));
  CHECK(p.lines[0].gamma == 3.0f);
  CHECK_FALSE(p.lines[0].closed);
  CHECK_FALSE(p.lines[0].hard);
  CHECK(p.lines[1].name == "crown");
  CHECK(p.lines[1].closed);
  CHECK(p.lines[1].hard);
  CHECK(p.lines[1].gamma == 1.0f);
  CHECK(p.lines[1].loc.line == 43);

  REQUIRE(g.effects.size() == 6);
  const EffectDesc &clump = g.effects[0];
  CHECK(clump.type == EffectType::clump);
  CHECK(clump.seed == 11);
  CHECK(clump.amount == 0.8f);
  CHECK(clump.ramp.t == std::vector<float>{0.0f, 0.5f, 1.0f});
  CHECK(clump.ramp.value == std::vector<float>{0.0f, 0.7f, 1.0f});
  CHECK(clump.groups == std::vector<std::string>{"scalp"});
  CHECK(clump.vertex_map_path == normal(fixtures / "density.txt"));
  CHECK(clump.clump_centers == EffectDesc::ClumpCenters::per_guide);
  CHECK(clump.clump_radius == 0.2f);
  CHECK(clump.clump_twist == 0.5f);
  CHECK(clump.stray_fraction == 0.1f);
  CHECK(clump.loc.line == 50);

  CHECK(g.effects[1].type == EffectType::tension);
  CHECK(g.effects[1].amount == 0.4f);
  CHECK(g.effects[1].ramp.t.empty());

  const EffectDesc &length = g.effects[2];
  CHECK(length.type == EffectType::length);
  CHECK(length.seed == 12);
  CHECK(length.length_distribution == EffectDesc::LengthDistribution::normal);
  CHECK(length.length_variation == 0.2f);
  CHECK(length.cut_plane);
  CHECK(length.cut_point.isApprox(Eigen::Vector3f(0, 0.8f, 0)));
  CHECK(length.cut_normal.isApprox(Eigen::Vector3f(0, 1, 0)));  // normalised
  CHECK(length.max_length == 0.9f);

  CHECK(g.effects[3].type == EffectType::wave);
  CHECK(g.effects[3].frequency == 4.0f);
  CHECK(g.effects[3].amplitude == 0.05f);
  CHECK(g.effects[4].type == EffectType::frizz);
  CHECK(g.effects[4].frequency == 40.0f);
  CHECK(g.effects[4].amplitude == 0.01f);
  CHECK(g.effects[4].fraction == 0.3f);
  CHECK(g.effects[5].type == EffectType::curl);
  CHECK(g.effects[5].curl_radius == 0.02f);
  CHECK(g.effects[5].turns_per_unit == 12.0f);

  const plume::DynamicsSettings &d = g.dynamics;
  CHECK(d.enabled);
  CHECK(d.substeps == 8);
  CHECK(d.fps == 30.0f);
  CHECK(d.preroll_frames == 12);
  CHECK(d.gravity.isApprox(Eigen::Vector3f(0, 0, -9.81f)));
  CHECK_FALSE(d.compensate_gravity);
  CHECK(d.stiffness.at(0.0f) == 2.0f);
  CHECK(d.stiffness.at(1.0f) == 0.5f);
  CHECK(d.stiffness_scale == 0.75f);
  CHECK(d.damping == 0.9f);
  CHECK(d.drag == 0.1f);
  CHECK(d.mass_per_unit == 2.0f);
  CHECK(d.wind.isApprox(Eigen::Vector3f(1, 0, 0)));
  CHECK(d.wind_gust == 0.3f);
  CHECK(d.wind_gust_frequency == 2.0f);
  CHECK(d.seed == 5);
  CHECK_FALSE(d.collide_with_emitter);
  CHECK(d.emitter_friction == 0.6f);
  CHECK(d.collision_margin == 0.02f);
  REQUIRE(d.shapes.size() == 2);
  CHECK(d.shapes[0].kind == plume::CollisionShape::Kind::sphere);
  CHECK(d.shapes[0].a.isApprox(Eigen::Vector3f(0, 1, 0)));
  CHECK(d.shapes[0].radius == 0.4f);
  CHECK(d.shapes[0].friction == 0.2f);
  CHECK(d.shapes[1].kind == plume::CollisionShape::Kind::capsule);
  CHECK(d.shapes[1].a.isApprox(Eigen::Vector3f(0, 0, 0)));
  CHECK(d.shapes[1].b.isApprox(Eigen::Vector3f(0, -1, 0)));
  CHECK(d.shapes[1].radius == 0.1f);
  CHECK(d.shapes[1].friction == 0.3f);
  CHECK(d.cache_pattern == normal(fixtures / "cache/guides.####.hair"));

  CHECK(g.output.path_pattern == normal(fixtures / "out/hair.####.usda"));
  CHECK(g.output.frames == "1-24:2");
  CHECK(g.output.preview_pattern == normal(fixtures / "out/preview.%04d.png"));
  CHECK(g.output.preview_every == 6);
  CHECK(g.output.preview_size == 400);
}

TEST_CASE("a minimal groom file gets the documented defaults", "[io]") {
  const GroomDesc g = read_groom_file((fixtures / "minimal.groom.yaml").string());
  const GroomDesc defaults;
  CHECK(g.name == "minimal");  // the file name without .groom.yaml
  CHECK(g.animation.kind == plume::EmitterAnimation::Kind::none);
  CHECK(g.roots.source == plume::RootSettings::Source::scatter);
  CHECK(g.roots.count == 0);
  CHECK(g.roots.density == 100.0);
  CHECK(g.roots.groups.empty());
  CHECK(g.roots.near_guides == 0.0);
  CHECK(g.roots.seed == 1);
  CHECK(g.points_per_strand == 32);
  CHECK(g.width_root < 0.0f);  // automatic: scaled to the emitter
  CHECK(g.width_tip < 0.0f);
  CHECK(g.interpolation.method == plume::InterpolationSettings::Method::streamline);
  CHECK(g.interpolation.k == 4);
  CHECK(g.interpolation.radius == 0.0);
  CHECK(g.interpolation.falloff == 2.0f);
  CHECK(g.interpolation.skin_margin < 0.0f);  // automatic: scaled to the guides
  CHECK(g.interpolation.separate);  // the separation pass is on unless the groom turns it off
  CHECK(g.partings.zone_source == plume::PartingSettings::ZoneSource::none);
  CHECK(g.partings.lines.empty());
  CHECK(g.effects.empty());
  CHECK_FALSE(g.dynamics.enabled);
  CHECK(g.dynamics.substeps == defaults.dynamics.substeps);
  CHECK(g.dynamics.gravity == defaults.dynamics.gravity);
  CHECK(g.dynamics.stiffness.t == defaults.dynamics.stiffness.t);
  CHECK(g.dynamics.stiffness.value == defaults.dynamics.stiffness.value);
  CHECK(g.dynamics.shapes.empty());
  CHECK(g.output.path_pattern.empty());
  CHECK(g.output.frames.empty());
  CHECK(g.output.preview_pattern.empty());
  CHECK(g.output.preview_every == 0);
  CHECK(g.output.preview_size == 800);
}

TEST_CASE("groom file defaults for effects and dynamics match the description structs", "[io]") {
  TempGroom t;
  const GroomDesc g = read_groom_file(t.write(
      "roots: {count: 10}\n"
      "effects: [{type: clump}, {type: length}, {type: frizz}, {type: curl}]\n"
      "dynamics: {}\n"));
  const EffectDesc e;
  REQUIRE(g.effects.size() == 4);
  for (const EffectDesc &x : g.effects) {
    CHECK(x.seed == e.seed);
    CHECK(x.amount == e.amount);
    CHECK(x.ramp.t.empty());
    CHECK(x.groups.empty());
    CHECK(x.vertex_map_path.empty());
  }
  CHECK(g.effects[0].clump_centers == e.clump_centers);
  CHECK(g.effects[0].clump_radius == e.clump_radius);
  CHECK(g.effects[0].clump_twist == e.clump_twist);
  CHECK(g.effects[0].stray_fraction == e.stray_fraction);
  CHECK(g.effects[1].length_distribution == e.length_distribution);
  CHECK(g.effects[1].length_variation == e.length_variation);
  CHECK_FALSE(g.effects[1].cut_plane);
  CHECK(g.effects[1].max_length == e.max_length);
  CHECK(g.effects[2].frequency == e.frequency);
  CHECK(g.effects[2].amplitude == e.amplitude);
  CHECK(g.effects[2].fraction == e.fraction);
  CHECK(g.effects[3].curl_radius == e.curl_radius);
  CHECK(g.effects[3].turns_per_unit == e.turns_per_unit);

  // An empty dynamics section turns the simulation on with every default.
  const plume::DynamicsSettings d;
  CHECK(g.dynamics.enabled);
  CHECK(g.dynamics.substeps == d.substeps);
  CHECK(g.dynamics.fps == d.fps);
  CHECK(g.dynamics.preroll_frames == d.preroll_frames);
  CHECK(g.dynamics.compensate_gravity == d.compensate_gravity);
  CHECK(g.dynamics.stiffness_scale == d.stiffness_scale);
  CHECK(g.dynamics.damping == d.damping);
  CHECK(g.dynamics.drag == d.drag);
  CHECK(g.dynamics.mass_per_unit == d.mass_per_unit);
  CHECK(g.dynamics.wind == d.wind);
  CHECK(g.dynamics.wind_gust == d.wind_gust);
  CHECK(g.dynamics.wind_gust_frequency == d.wind_gust_frequency);
  CHECK(g.dynamics.seed == d.seed);
  CHECK(g.dynamics.collide_with_emitter == d.collide_with_emitter);
  CHECK(g.dynamics.emitter_friction == d.emitter_friction);
  CHECK(g.dynamics.collision_margin == d.collision_margin);
  CHECK(g.dynamics.cache_pattern.empty());
}

TEST_CASE("groom file paths are resolved against the groom file's folder", "[io]") {
  TempGroom t;
  fs::create_directories(t.folder() / "assets" / "anim");
  fs::copy_file(fixtures / "head.obj", t.folder() / "assets" / "head.obj");
  fs::copy_file(fixtures / "guides.obj", t.folder() / "assets" / "guides.obj");
  fs::copy_file(fixtures / "roots.txt", t.folder() / "roots.txt");
  fs::copy_file(fixtures / "zones.txt", t.folder() / "assets" / "zones.txt");
  const std::string path = t.write(
      "plume: 1\n"
      "emitter:\n"
      "  mesh: assets/head.obj\n"
      "  animation: {sequence: assets/anim/head.####.obj}\n"
      "guides: {file: ./assets/../assets/guides.obj}\n"
      "roots: {file: roots.txt}\n"
      "partings: {zones: {from: map, map: assets/zones.txt}}\n"
      "dynamics: {enabled: false, cache: cache/g.%04d.usda}\n"
      "output: {path: ../elsewhere/hair.####.ply}\n",
      false);
  // Read through a relative path too: the result is absolute either way.
  const fs::path cwd = fs::current_path();
  fs::current_path(t.folder());
  const GroomDesc relative = read_groom_file("test.groom.yaml");
  fs::current_path(cwd);
  const GroomDesc g = read_groom_file(path);
  const fs::path folder = fs::absolute(t.folder()).lexically_normal();
  for (const GroomDesc *x : {&g, &relative}) {
    CHECK(x->source == (folder / "test.groom.yaml").string());
    CHECK(x->emitter_path == (folder / "assets/head.obj").string());
    CHECK(x->animation.kind == plume::EmitterAnimation::Kind::obj_sequence);
    CHECK(x->animation.sequence_pattern == (folder / "assets/anim/head.####.obj").string());
    CHECK(x->guides_path == (folder / "assets/guides.obj").string());
    CHECK(x->roots.source == plume::RootSettings::Source::file);
    CHECK(x->roots.file == (folder / "roots.txt").string());
    CHECK(x->partings.zone_source == plume::PartingSettings::ZoneSource::zone_map);
    CHECK(x->partings.zone_map_path == (folder / "assets/zones.txt").string());
    CHECK_FALSE(x->dynamics.enabled);
    CHECK(x->dynamics.cache_pattern == (folder / "cache/g.%04d.usda").string());
    CHECK(x->output.path_pattern == (folder.parent_path() / "elsewhere/hair.####.ply").string());
  }
}

TEST_CASE("groom file: stiffness as a ramp, zones from hard lines, keys given without a value", "[io]") {
  TempGroom t;
  const GroomDesc g = read_groom_file(t.write(
      "name:\n"
      "roots: {count: 10, groups: face}\n"
      "strands:\n"
      "partings:\n"
      "  zones: {from: lines}\n"
      "  lines: [{points: [[0, 0, 0], [1, 0, 1]], hard: true}, {points: [[0, 0, 1], [1, 0, 0]]}]\n"
      "dynamics:\n"
      "  stiffness: [[0, 3], [0.5, 1], [1, 0.25]]\n"));
  CHECK(g.name == "test");
  CHECK(g.roots.groups == std::vector<std::string>{"face"});
  CHECK(g.partings.zone_source == plume::PartingSettings::ZoneSource::lines);
  REQUIRE(g.partings.lines.size() == 2);
  CHECK(g.partings.lines[0].name == "line0");  // unnamed lines are numbered
  CHECK(g.partings.lines[1].name == "line1");
  CHECK(g.partings.lines[1].gamma == 2.0f);
  CHECK(g.dynamics.stiffness.t == std::vector<float>{0.0f, 0.5f, 1.0f});
  CHECK(g.dynamics.stiffness.value == std::vector<float>{3.0f, 1.0f, 0.25f});
  CHECK(g.dynamics.stiffness_scale == 1.0f);

  const GroomDesc h = read_groom_file(t.write(
      "roots: {count: 10}\n"
      "dynamics: {stiffness: {ramp: [[0, 2], [1, 2]], scale: 3}}\n"));
  CHECK(h.dynamics.stiffness.value == std::vector<float>{2.0f, 2.0f});
  CHECK(h.dynamics.stiffness_scale == 3.0f);
}

TEST_CASE("broken groom fixtures name the file, line:column, key path and what was expected", "[io]") {
  check_bad("unknown_top_key.groom.yaml", "6:1", "strand", "unknown key; expected one of:");
  check_bad("unknown_effect_key.groom.yaml", "10:5", "effects[1].amout", "unknown key");
  check_bad("wrong_type_count.groom.yaml", "6:10", "roots.count", "expected a whole number in [1, 100000000], got \"many\"");
  check_bad("points_out_of_range.groom.yaml", "7:11", "strands.points", "expected a whole number in [2, 65536], got \"1\"");
  check_bad("huge_count.groom.yaml", "5:16", "roots.count", "expected a whole number in [1, 100000000], got \"1e12\"");
  check_bad("missing_mesh.groom.yaml", "4:3", "emitter.mesh", "missing required key");
  check_bad("missing_guides_file.groom.yaml", "5:9", "guides.file",
            "expected an existing file, got \"../groom_file/no_such_guides.hair\" (" +
                normal(data_dir / "groom_file/no_such_guides.hair") + " does not exist)");
  check_bad("effect_key_of_other_type.groom.yaml", "9:5", "effects[0].radius",
            "expected a key of a wave effect (type, seed, amount, ramp, groups, map, frequency, amplitude, fraction), "
            "got radius (a key of clump, curl)");
  check_bad("effect_wrong_type.groom.yaml", "10:16", "effects[2].amplitude", "expected a number, got \"strong\"");
  check_bad("nan_in_vector.groom.yaml", "7:16", "dynamics.gravity[1]", "expected a finite number, got \"nan\"");
  check_bad("inf_in_shape.groom.yaml", "9:28", "dynamics.shapes[1].sphere.center[1]", "expected a finite number, got \"inf\"");
  check_bad("unsorted_ramp.groom.yaml", "8:33", "effects[0].ramp[2][0]",
            "expected t in [0.6, 1] (t sorted from root to tip), got \"0.3\"");
  check_bad("negative_radius.groom.yaml", "8:53", "dynamics.shapes[0].capsule.radius", "expected a number > 0, got \"-0.5\"");
  check_bad("duplicate_key.groom.yaml", "8:3", "interpolation.k", "duplicate key (first given at line 7)");
  check_bad("missing_version.groom.yaml", "2:1", "plume", "missing required key");
}

TEST_CASE("a YAML syntax error becomes an InputError at its line:column", "[io]") {
  const std::string path = (data_dir / "bad/syntax_error.groom.yaml").string();
  const std::string message = error_of(path);
  INFO(message);
  std::string pattern = "^";
  pattern.append(std::regex_replace(path, std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)"));
  pattern.append(R"(:5:\d+: YAML syntax error: )");
  CHECK(std::regex_search(message, std::regex(pattern)));
}

TEST_CASE("a missing groom file is an InputError naming it", "[io]") {
  const std::string path = (data_dir / "groom_file/no_such.groom.yaml").string();
  CHECK(error_of(path) == path + ": cannot read the groom file: no such file");
}

TEST_CASE("a file that is not a groom is not echoed whole in the message", "[io]") {
  // An OBJ reads as YAML as one long plain scalar (its lines folded into one); the message shows
  // its start and its size.
  TempGroom t;
  std::string obj = "o head\n";
  for (int v = 0; v < 1000; ++v) obj += "v " + std::to_string(v) + " 0 0\n";
  const std::string path = t.write(obj, false);
  const std::string message = error_of(path);
  INFO(message);
  CHECK(message.rfind(path + ":", 0) == 0);
  CHECK(message.find("groom: expected a map of key: value, got \"o head v 0 0 0 v 1 0 0 ") != std::string::npos);
  CHECK(message.find("...\" (") != std::string::npos);
  CHECK(message.find(" characters)") != std::string::npos);
  CHECK(message.size() < path.size() + 200);
  // Control characters in a value are shown escaped.
  const std::string tab = t.write("roots: {count: \"1\\t0\"}\n");
  CHECK(error_of(tab).find("roots.count: expected a whole number in [1, 100000000], got \"1\\x090\"") != std::string::npos);
}

TEST_CASE("every groom fixture in tests/data/bad fails with a located message", "[io]") {
  int count = 0;
  for (const fs::directory_entry &entry : fs::directory_iterator(data_dir / "bad")) {
    const std::string name = entry.path().filename().string();
    if (name.size() < 11 || name.compare(name.size() - 11, 11, ".groom.yaml") != 0) continue;
    ++count;
    const std::string message = error_of(entry.path().string());
    INFO(name << ": " << message);
    CHECK(std::regex_search(message, std::regex(R"(\.groom\.yaml:\d+:\d+: )")));
  }
  CHECK(count >= 16);
}

TEST_CASE("groom file rules between keys are errors with key paths", "[io]") {
  TempGroom t;
  const std::vector<KeyErrorCase> cases{
      {"roots: {count: 10, density: 5}\n", "roots", "expected one of count, density or file"},
      {"roots: {groups: [scalp]}\n", "roots", "expected one of count, density or file"},
      {"roots: {file: " + (fixtures / "roots.txt").string() + ", count: 5}\n", "roots.count", "not allowed with roots.file"},
      {"roots: {file: " + (fixtures / "head.obj").string() + "x}\n", "roots.file", "expected a file ending in .hair, .ply, .usda, .obj, .txt"},
      {"roots: {density: -1}\n", "roots.density", "expected a number in [0, 1e+08]"},
      {"roots: {count: 2.5}\n", "roots.count", "expected a whole number"},
      {"roots: {count: 10}\nplume: 1\n", "plume", "duplicate key"},
      {"roots: {count: 10}\nstrands: {width: {root: -0.1}}\n", "strands.width.root", "expected a number >= 0"},
      {"roots: {count: 10, groups: [scalp, \"a\\0b\"]}\n", "roots.groups[1]",
       "expected a name without control characters, got \"a\\x00b\""},
      {"roots: {count: 10}\neffects: [{type: wave}, {type: curl, groups: \"hair\\nline\"}]\n", "effects[1].groups",
       "expected a name without control characters, got \"hair\\x0aline\""},
      {"roots: {count: 10}\nstrands: {points: 65537}\n", "strands.points", "expected a whole number in [2, 65536]"},
      {"roots: {count: 10}\ninterpolation: {method: nearest}\n", "interpolation.method", "expected one of streamline, fur, linear"},
      {"roots: {count: 10}\ninterpolation: {k: 17}\n", "interpolation.k", "expected a whole number in [1, 16]"},
      {"roots: {count: 10}\ninterpolation: {falloff: 0}\n", "interpolation.falloff", "expected a number > 0"},
      {"roots: {count: 10}\npartings: {lines: [{points: [[0, 0, 0], [1, 0, 0]], gamma: 0.5}]}\n",
       "partings.lines[0].gamma", "expected a number >= 1"},
      {"roots: {count: 10}\npartings: {lines: [{points: [[0, 0, 0], [1, 0, 0]], closed: true}]}\n",
       "partings.lines[0].points", "expected a list of at least 3 points [x, y, z] (a closed line), got 2"},
      {"roots: {count: 10}\npartings: {lines: [{name: a, points: [[0, 0, 0], [1, 0, 0]]}, {name: a, points: [[0, 0, 0], [1, 0, 0]]}]}\n",
       "partings.lines[1].name", "expected a name no other parting line has"},
      {"roots: {count: 10}\npartings: {zones: {from: lines}, lines: [{points: [[0, 0, 0], [1, 0, 0]]}]}\n",
       "partings.zones.from", "hard: true"},
      {"roots: {count: 10}\npartings: {zones: {from: map}}\n", "partings.zones.map", "missing required key"},
      {"roots: {count: 10}\npartings: {zones: {from: groups, map: zones.txt}}\n", "partings.zones.map", "not allowed unless zones.from is map"},
      {"roots: {count: 10}\npartings: {zones: {from: map, map: nothing.txt}}\n", "partings.zones.map", "expected an existing file"},
      {"roots: {count: 10}\neffects: [{amount: 0.5}]\n", "effects[0].type", "missing required key"},
      {"roots: {count: 10}\neffects: [{type: braid}]\n", "effects[0].type", "expected one of clump, tension, length, wave, frizz, curl"},
      {"roots: {count: 10}\neffects: [{type: tension, amount: 1.5}]\n", "effects[0].amount", "expected a number in [0, 1]"},
      {"roots: {count: 10}\neffects: [{type: tension, map: missing.txt}]\n", "effects[0].map", "expected an existing file"},
      {"roots: {count: 10}\neffects: [{type: tension, ramp: [[0, 1], [1, 2]]}]\n", "effects[0].ramp[1][1]", "expected a value in [0, 1]"},
      {"roots: {count: 10}\neffects: [{type: tension, ramp: [[0, 1, 2]]}]\n", "effects[0].ramp[0]", "expected a [t, value] pair"},
      {"roots: {count: 10}\neffects: [{type: tension, ramp: []}]\n", "effects[0].ramp", "expected a list of [t, value] points"},
      {"roots: {count: 10}\neffects: [{type: length, cut: {normal: [0, 0, 0]}}]\n", "effects[0].cut.normal", "expected a non-zero vector"},
      {"roots: {count: 10}\neffects: [{type: tension, frequency: 2}]\n", "effects[0].frequency", "got frequency (a key of frizz, wave)"},
      {"roots: {count: 10}\nemitter: {mesh: x.obj}\n", "emitter", "duplicate key"},
      {"roots: {count: 10}\ndynamics: {substeps: 0}\n", "dynamics.substeps", "expected a whole number in [1, 1000]"},
      {"roots: {count: 10}\ndynamics: {fps: 0}\n", "dynamics.fps", "expected a number > 0"},
      {"roots: {count: 10}\ndynamics: {gravity: [0, -9.8]}\n", "dynamics.gravity", "expected a list of 3 numbers [x, y, z]"},
      {"roots: {count: 10}\ndynamics: {gravity: [0, 1e39, 0]}\n", "dynamics.gravity[1]", "expected a finite number"},
      {"roots: {count: 10}\ndynamics: {stiffness: {root: 1, ramp: [[0, 1]]}}\n", "dynamics.stiffness.root", "not allowed with stiffness.ramp"},
      {"roots: {count: 10}\ndynamics: {stiffness: [[0, -1]]}\n", "dynamics.stiffness[0][1]", "expected a value >= 0"},
      {"roots: {count: 10}\ndynamics: {wind: {speed: 3}}\n", "dynamics.wind.speed", "unknown key"},
      {"roots: {count: 10}\ndynamics: {shapes: [{sphere: {center: [0, 0, 0], radius: 1}, capsule: {a: [0, 0, 0], b: [0, 1, 0]}}]}\n",
       "dynamics.shapes[0]", "either sphere"},
      {"roots: {count: 10}\ndynamics: {shapes: [{capsule: {a: [0, 0, 0], radius: 1}}]}\n", "dynamics.shapes[0].capsule.b", "missing required key"},
      {"roots: {count: 10}\ndynamics: {cache: cache/guides.hair}\n", "dynamics.cache", "expected a path with a frame field"},
      {"roots: {count: 10}\noutput: {path: out/hair.####.abc}\n", "output.path", "expected a path ending in .usda, .hair, .ply, .obj"},
      {"roots: {count: 10}\noutput: {preview: out/p.jpg}\n", "output.preview", "expected a path ending in .png"},
      {"roots: {count: 10}\noutput: {frames: 48-1}\n", "output.frames", "expected a frame range A, A-B, A-B:S or A-BxS"},
      {"roots: {count: 10}\noutput: {frames: 1-48:0}\n", "output.frames", "expected a frame range"},
      {"roots: {count: 10}\noutput: {preview_size: 8}\n", "output.preview_size", "expected a whole number in [16, 8192]"},
  };
  check_key_errors(t, cases);
}

TEST_CASE("numbers beyond their documented bounds are errors naming the file, line and key", "[io]") {
  // Each value is a finite 32-bit float that growth used to turn into inf or NaN points (an
  // internal error), or a number too large for a float that was accepted.
  TempGroom t;
  const std::string r = "roots: {count: 10}\n";
  const std::vector<KeyErrorCase> cases{
      {r + "interpolation: {method: fur, falloff: 1e12}\n", "interpolation.falloff", "expected a number in (0, 4], got \"1e12\""},
      {r + "interpolation: {skin_margin: 1e30}\n", "interpolation.skin_margin", "expected a number in [0, 1e+06]"},
      {r + "interpolation: {separate: 2}\n", "interpolation.separate", "true or false"},
      {r + "interpolation: {radius: 1e39}\n", "interpolation.radius", "expected a finite number, got \"1e39\""},
      {r + "interpolation: {radius: 1e7}\n", "interpolation.radius", "expected a number in [0, 1e+06]"},
      {"roots: {count: 0}\n", "roots.count", "expected a whole number in [1, 100000000], got \"0\""},
      {"roots: {count: 10, near_guides: 1e39}\n", "roots.near_guides", "expected a finite number, got \"1e39\""},
      {"roots: {count: 10, near_guides: 1e7}\n", "roots.near_guides", "expected a number in [0, 1e+06]"},
      {r + "strands: {width: {tip: 1e20}}\n", "strands.width.tip", "expected a number in [0, 1e+06]"},
      {r + "effects: [{type: wave, frequency: 4, amplitude: 1e20}]\n", "effects[0].amplitude", "expected a number in [0, 1e+06]"},
      {r + "effects: [{type: frizz, frequency: 40, amplitude: 1e20}]\n", "effects[0].amplitude", "expected a number in [0, 1e+06]"},
      {r + "effects: [{type: frizz, frequency: 1e5}]\n", "effects[0].frequency", "expected a number in (0, 1000]"},
      {r + "effects: [{type: clump, centers: per_guide, twist: 1e12}]\n", "effects[0].twist", "expected a number in [-1000, 1000]"},
      {r + "effects: [{type: clump, radius: 1e20}]\n", "effects[0].radius", "expected a number in (0, 1e+06]"},
      {r + "effects: [{type: curl, radius: 1e20, turns_per_unit: 1}]\n", "effects[0].radius", "expected a number in [0, 1e+06]"},
      {r + "effects: [{type: curl, radius: 0.1, turns_per_unit: 1e12}]\n", "effects[0].turns_per_unit", "expected a number in [0, 1000]"},
      {r + "effects: [{type: length, max_length: 1e30}]\n", "effects[0].max_length", "expected a number in [0, 1e+06]"},
      {r + "effects: [{type: length, cut: {point: [0, 1e20, 0]}}]\n", "effects[0].cut.point[1]", "expected a coordinate in [-1e+06, 1e+06]"},
      {r + "effects: [{type: length, cut: {normal: [0, 1e30, 0]}}]\n", "effects[0].cut.normal[1]", "expected a number in [-1e+06, 1e+06]"},
      {r + "partings: {lines: [{points: [[0, 0, 0], [1e30, 0, 0]]}]}\n", "partings.lines[0].points[1][0]",
       "expected a coordinate in [-1e+06, 1e+06]"},
      {r + "dynamics: {shapes: [{sphere: {center: [0, 0, 1e20]}}]}\n", "dynamics.shapes[0].sphere.center[2]", "expected a coordinate"},
      {r + "dynamics: {shapes: [{capsule: {a: [0, 0, 0], b: [0, 0, 1e20]}}]}\n", "dynamics.shapes[0].capsule.b[2]", "expected a coordinate"},
      {r + "dynamics: {gravity: [0, -1e30, 0]}\n", "dynamics.gravity[1]", "expected a number in [-1e+06, 1e+06]"},
      {r + "dynamics: {damping: 1e30}\n", "dynamics.damping", "expected a number in [0, 1e+06]"},
      {r + "dynamics: {stiffness: [[0, 1e30]]}\n", "dynamics.stiffness[0][1]", "expected a value in [0, 1e+06]"},
      {r + "output: {frames: 1}\neffects: [{type: tension, ramp: [[1e39, 1]]}]\n", "effects[0].ramp[0][0]", "expected a finite number"},
  };
  check_key_errors(t, cases);
  // The bounds themselves are accepted.
  const GroomDesc g = read_groom_file(t.write(
      "roots: {count: 10, near_guides: 1e6}\n"
      "interpolation: {method: fur, k: 16, falloff: 4, radius: 1e6, skin_margin: 1e6}\n"
      "effects: [{type: clump, twist: -1000, radius: 1e6}, {type: curl, radius: 1e6, turns_per_unit: 1000},\n"
      "          {type: wave, frequency: 1000, amplitude: 1e6}]\n"));
  CHECK(g.interpolation.k == 16);
  CHECK(g.interpolation.falloff == 4.0f);
  CHECK(g.effects[0].clump_twist == -1000.0f);
  CHECK(g.effects[1].turns_per_unit == 1000.0f);
}

TEST_CASE("a bad zone group is reported under its real key, partings.zones.groups", "[io]") {
  TempGroom t;
  const GroomDesc g = read_groom_file(t.write("roots: {count: 10}\npartings:\n  zones: {from: groups, groups: [nope]}\n"));
  CHECK(g.partings.zone_groups_loc.line == 6);
  CHECK(g.partings.zone_groups_loc.file == t.folder().string() + "/test.groom.yaml");
}

TEST_CASE("groom file animation rules", "[io]") {
  TempGroom t;
  const std::string mesh = (fixtures / "head.obj").string();
  const std::string guides = "guides: {file: " + (fixtures / "guides.obj").string() + "}\nroots: {count: 1}\n";
  struct Case {
    std::string emitter;
    std::string key_path;
    std::string expected;
  };
  const std::vector<Case> cases{
      {"{mesh: " + mesh + ", animation: {}}", "emitter.animation", "expected either sequence or keys"},
      {"{mesh: " + mesh + ", animation: {sequence: a.####.obj, keys: [{frame: 1}]}}", "emitter.animation", "not both"},
      {"{mesh: " + mesh + ", animation: {sequence: head.obj}}", "emitter.animation.sequence", "with a frame field"},
      {"{mesh: " + mesh + ", animation: {sequence: a.####.obj, pivot: [0, 0, 0]}}", "emitter.animation.pivot", "not allowed"},
      {"{mesh: " + mesh + ", animation: {keys: []}}", "emitter.animation.keys", "expected a list of at least one key"},
      {"{mesh: " + mesh + ", animation: {keys: [{translate: [0, 0, 0]}]}}", "emitter.animation.keys[0].frame", "missing required key"},
      {"{mesh: " + mesh + ", animation: {keys: [{frame: 5}, {frame: 5}]}}", "emitter.animation.keys[1].frame",
       "expected a frame after 5 (keys sorted by frame)"},
      {"{mesh: " + mesh + ", animation: {keys: [{frame: 1, scale: 0}]}}", "emitter.animation.keys[0].scale", "expected a number in [0.01, 100]"},
      {"{mesh: " + mesh + ", animation: {keys: [{frame: 1, scale: 1e-30}]}}", "emitter.animation.keys[0].scale",
       "expected a number in [0.01, 100], got \"1e-30\""},
      {"{mesh: " + mesh + ", animation: {keys: [{frame: 1, scale: 1e30}]}}", "emitter.animation.keys[0].scale", "expected a number in [0.01, 100]"},
      {"{mesh: " + mesh + ", animation: {keys: [{frame: 1, translate: [1e30, 0, 0]}]}}",
       "emitter.animation.keys[0].translate[0]", "expected a coordinate in [-1e+06, 1e+06], got \"1e30\""},
      {"{mesh: " + mesh + ", animation: {keys: [{frame: 1}], pivot: [0, 2e6, 0]}}", "emitter.animation.pivot[1]",
       "expected a coordinate in [-1e+06, 1e+06]"},
      {"{mesh: " + mesh + ", animation: {keys: [{frame: 1, rotate: [0, 0, 1e20]}]}}", "emitter.animation.keys[0].rotate[2]",
       "expected a number in [-1e+06, 1e+06]"},
      {"{mesh: " + mesh + ", animation: {keys: [{frame: 1, rotation: [0, 0, 0]}]}}", "emitter.animation.keys[0].rotation", "unknown key"},
      {"{mesh: " + (fixtures / "guides.hair").string() + "}", "emitter.mesh", "expected a file ending in .obj"},
      {"{mesh: " + (fixtures / "nowhere.obj").string() + "}", "emitter.mesh", "does not exist"},
      {"{mesh: " + fixtures.string() + "/}", "emitter.mesh", "expected a file ending in .obj"},
  };
  for (const Case &c : cases) {
    const std::string message = error_of(t.write("plume: 1\nemitter: " + c.emitter + "\n" + guides, false));
    INFO(c.emitter << " -> " << message);
    CHECK(message.find(": " + c.key_path + ": ") != std::string::npos);
    CHECK(message.find(c.expected) != std::string::npos);
  }
  CHECK(error_of(t.write("plume: 2\nemitter: {mesh: " + mesh + "}\n" + guides, false)).find("plume: expected the format version 1, got \"2\"") !=
        std::string::npos);
  CHECK(error_of(t.write("", false)).find("plume: missing required key") != std::string::npos);
  CHECK(error_of(t.write("- a\n- b\n", false)).find(":1:1: groom: expected a map of key: value, got a list") != std::string::npos);
}

TEST_CASE("describe_groom lists what a groom does", "[io]") {
  const GroomDesc g = read_groom_file((fixtures / "full.groom.yaml").string());
  const std::string text = plume::io::describe_groom(g);
  CHECK(text.find("groom: full test groom") != std::string::npos);
  CHECK(text.find("2 rigid keys") != std::string::npos);
  CHECK(text.find("roots: 1500 scattered on scalp") != std::string::npos);
  CHECK(text.find("strands: 16 points") != std::string::npos);
  CHECK(text.find("interpolation: fur, k 6") != std::string::npos);
  CHECK(text.find("effects: clump(0.8) tension(0.4) length(1) wave(1) frizz(1) curl(1)") != std::string::npos);
  CHECK(text.find("dynamics: 8 substeps at 30 fps, 2 collision shapes\n") != std::string::npos);
  CHECK(text.find("frames 1-24:2") != std::string::npos);
}

TEST_CASE("the full example of docs/groom-format.md is a valid groom", "[io]") {
  std::ifstream in(fs::path(PLUME_SOURCE_DIR) / "docs" / "groom-format.md");
  REQUIRE(in);
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string opening = "## A full example";
  const size_t section = doc.find(opening);
  REQUIRE(section != std::string::npos);
  const size_t begin = doc.find("```yaml\n", section);
  REQUIRE(begin != std::string::npos);
  const size_t end = doc.find("```", begin + 8);
  REQUIRE(end != std::string::npos);
  const std::string example = doc.substr(begin + 8, end - begin - 8);

  // The files the example reads must exist; their content is not the groom reader's business.
  TempGroom t;
  for (const char *name : {"head.obj", "guides.hair", "clump_density.txt"}) std::ofstream(t.folder() / name) << "\n";
  const GroomDesc g = read_groom_file(t.write(example, false));
  CHECK(g.name == "example");
  CHECK(g.roots.count == 30000);
  CHECK(g.partings.zone_source == plume::PartingSettings::ZoneSource::face_groups);
  CHECK(g.effects.size() == 6);
  CHECK(g.dynamics.enabled);
  CHECK(g.dynamics.shapes.size() == 2);
  CHECK(g.output.frames == "1-48");
}

TEST_CASE("every groom in grooms/ is a valid groom file", "[io]") {
  int count = 0;
  for (const fs::directory_entry &entry : fs::recursive_directory_iterator(fs::path(PLUME_SOURCE_DIR) / "grooms")) {
    const std::string name = entry.path().filename().string();
    if (name.size() < 11 || name.compare(name.size() - 11, 11, ".groom.yaml") != 0) continue;
    INFO(entry.path().string());
    CHECK_NOTHROW(read_groom_file(entry.path().string()));
    ++count;
  }
  CHECK(count >= 1);
}

TEST_CASE("dynamics.cache takes the four strand formats, as plume simulate --cache does", "[io]") {
  TempGroom t;
  for (const std::string ext : {".hair", ".usda", ".ply", ".obj"}) {
    const GroomDesc g = read_groom_file(t.write("roots: {count: 10}\ndynamics: {cache: cache/g.####" + ext + "}\n"));
    CHECK(g.dynamics.cache_pattern.size() > ext.size());
    CHECK(g.dynamics.cache_pattern.compare(g.dynamics.cache_pattern.size() - ext.size(), ext.size(), ext) == 0);
  }
  check_key_errors(t, {{"roots: {count: 10}\ndynamics: {cache: cache/g.####.abc}\n", "dynamics.cache",
                        "expected a path ending in .hair, .usda, .ply, .obj"}});
}
