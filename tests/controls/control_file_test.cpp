// The controls section of a groom file: every key read, and every bad value reported with the
// file, line, column and key path (exit 2 from the plume command).
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "groom/error.h"
#include "io/control_section.h"
#include "io/groom_file.h"
#include "io/scratch_dir.h"

using namespace plume;

namespace {

namespace fs = std::filesystem;

const std::string kData = PLUME_TEST_DATA;

// A groom on the test head with `controls` (and `extra`) appended; returns its path.
std::string write_groom(const test::ScratchDir &dir, const std::string &controls, const std::string &extra = "") {
  const std::string path = dir.file("c.groom.yaml");
  std::ofstream out(path);
  out << "plume: 1\n"
      << "emitter: {mesh: " << kData << "/groom_file/head.obj}\n"
      << "guides: {file: " << kData << "/groom_file/guides.obj}\n"
      << "roots: {count: 10}\n"
      << extra << "controls:\n"
      << controls;
  return path;
}

std::string error_of(const std::string &path) {
  try {
    io::read_groom_file(path);
  } catch (const InputError &e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("the controls section reads every key", "[controls][io]") {
  const test::ScratchDir dir("controls_keys");
  std::ofstream(dir.file("weights.txt")) << "0\n0.5\n1\n1\n";
  const std::string path = write_groom(dir, R"(  binding: nearest
  list:
    - name: spine
      place: skin
      position: [0.5, 0.1, 0.5]
      offset: {keys: [[1, [0, 0, 0]], [12, [0, 2, 0]]], interpolation: smooth}
      radius: 0.8
      falloff: linear
      groups: [scalp]
      map: weights.txt
      mirror: {point: [0.5, 0, 0], normal: [2, 0, 0]}
      lift: {by: angle, keys: [[1, 0], [6, 45], [12, 90]], interpolation: smooth}
      aim: [[1, 0], [10, 1]]
      direction: 0.5
      random_twist: {amount: 30, seed: 7}
      dynamic_blend: {keys: [[1, 0], [5, 1]], ramp: [[0, 0], [0.5, 0.2], [1, 1]]}
    - position: [0, 3, 0]
      place: space
      mirror: z
      aim: 1
)",
                                       "dynamics: {}\n");
  const GroomDesc g = io::read_groom_file(path);
  REQUIRE(g.controls.controls.size() == 2);
  CHECK(g.controls.binding == ControlSettings::Binding::nearest);
  const ControlDesc &a = g.controls.controls[0];
  CHECK(a.name == "spine");
  CHECK(a.place == ControlDesc::Place::skin);
  CHECK(a.position.isApprox(Eigen::Vector3f(0.5f, 0.1f, 0.5f)));
  CHECK(a.offset.frames == std::vector<double>{1, 12});
  CHECK(a.offset.values[1].isApprox(Eigen::Vector3f(0, 2, 0)));
  CHECK(a.offset.interpolation == KeyInterpolation::smooth);
  CHECK(a.radius == 0.8f);
  CHECK(a.falloff == ControlDesc::Falloff::linear);
  CHECK(a.groups == std::vector<std::string>{"scalp"});
  CHECK(a.vertex_map_path == (fs::path(dir.path()) / "weights.txt").lexically_normal().string());
  CHECK(a.mirror);
  CHECK(a.mirror_normal.isApprox(Eigen::Vector3f::UnitX()));
  CHECK(a.mirror_point.isApprox(Eigen::Vector3f(0.5f, 0, 0)));
  CHECK(a.lift_by == ControlDesc::LiftBy::angle);
  CHECK(a.lift.values == std::vector<float>{0, 45, 90});
  CHECK(a.lift.interpolation == KeyInterpolation::smooth);
  CHECK(a.aim.frames == std::vector<double>{1, 10});
  CHECK(a.aim.interpolation == KeyInterpolation::linear);
  CHECK(a.direction.values == std::vector<float>{0.5f});
  CHECK(a.random_twist.values == std::vector<float>{30});
  CHECK(a.twist_seed == 7);
  CHECK(a.dynamic_blend.frames == std::vector<double>{1, 5});
  CHECK(a.blend_ramp.at(0.5f) == Approx(0.2f));
  const ControlDesc &b = g.controls.controls[1];
  CHECK(b.name == "control1");
  CHECK(b.place == ControlDesc::Place::space);
  CHECK(b.radius == 0.0f);
  CHECK(b.mirror_normal.isApprox(Eigen::Vector3f::UnitZ()));
  CHECK(b.lift.empty());
  CHECK(io::describe_groom(g).find("controls: 2, nearest binding") != std::string::npos);

  const auto maps = io::read_control_maps(g.controls, 4);
  REQUIRE(maps.size() == 2);
  CHECK(maps[0] == std::vector<float>{0.0f, 0.5f, 1.0f, 1.0f});
  CHECK(maps[1].empty());
  CHECK_THROWS_WITH(io::read_control_maps(g.controls, 5),
                    Catch::Contains(".txt: expected 5 values (one per emitter vertex), got 4"));
}

TEST_CASE("bad control files are rejected with file:line:column and the key", "[controls][io]") {
  struct Bad {
    const char *name;
    const char *expected;
  };
  const Bad files[] = {
      {"controls_zero_radius.groom.yaml",
       ":8:54: controls.list[0].radius: expected a number in (0, 1e+06] (leave radius out for a control that reaches "
       "every guide), got \"0\""},
      {"controls_unsorted_keys.groom.yaml",
       ":10:32: controls.list[0].lift[2][0]: expected a frame after the previous key's (12), got \"6\""},
      {"controls_blend_without_dynamics.groom.yaml",
       ":10:22: controls.list[0].dynamic_blend: expected a groom with dynamics"},
      {"controls_lift_out_of_range.groom.yaml",
       ":10:34: controls.list[0].lift.keys[1][1]: expected a number in [-1, 1], got \"45\""},
  };
  for (const Bad &bad : files) {
    const std::string message = error_of(kData + "/bad/" + bad.name);
    INFO(message);
    CHECK(message.find(std::string(bad.name) + bad.expected) != std::string::npos);
  }
}

TEST_CASE("every bad value of a control names its key", "[controls][io]") {
  const test::ScratchDir dir("controls_bad");
  struct Case {
    std::string yaml, expected;
  };
  const Case cases[] = {
      {"  list:\n    - {lift: 1}\n", "controls.list[0].position: missing required key"},
      {"  list:\n    - {position: [0, 0, 0], lfit: 1}\n", "controls.list[0].lfit: unknown key; expected one of:"},
      {"  binding: closest\n", "controls.binding: expected one of nearest, blend, got \"closest\""},
      {"  list:\n    - {position: [0, 0, nan]}\n", "controls.list[0].position[2]: expected a finite number"},
      {"  list:\n    - {position: [0, 0, 2e6]}\n",
       "controls.list[0].position[2]: expected a coordinate in [-1e+06, 1e+06]"},
      {"  list:\n    - {position: [0, 0, 0], place: air}\n", "controls.list[0].place: expected one of skin, space"},
      {"  list:\n    - {position: [0, 0, 0], falloff: linear}\n",
       "controls.list[0].falloff: not allowed without radius"},
      {"  list:\n    - {position: [0, 0, 0], radius: -1}\n",
       "controls.list[0].radius: expected a number in (0, 1e+06]"},
      {"  list:\n    - {position: [0, 0, 0], mirror: w}\n", "controls.list[0].mirror: expected one of x, y, z"},
      {"  list:\n    - {position: [0, 0, 0], mirror: {normal: [0, 0, 0]}}\n",
       "controls.list[0].mirror.normal: expected a non-zero vector"},
      {"  list:\n    - {position: [0, 0, 0], aim: 1.5}\n",
       "controls.list[0].aim: expected a number in [0, 1], got \"1.5\""},
      {"  list:\n    - {position: [0, 0, 0], aim: strong}\n", "controls.list[0].aim: expected a number"},
      {"  list:\n    - {position: [0, 0, 0], aim: {amount: 1, keys: [[1, 1]]}}\n",
       "controls.list[0].aim: expected a map with either amount"},
      {"  list:\n    - {position: [0, 0, 0], aim: {amount: 1, by: angle}}\n", "controls.list[0].aim.by: unknown key"},
      {"  list:\n    - {position: [0, 0, 0], aim: [[1, 0], [1, 1]]}\n",
       "controls.list[0].aim[1][0]: expected a frame after the previous key's (1)"},
      {"  list:\n    - {position: [0, 0, 0], aim: [[1e10, 0]]}\n",
       "controls.list[0].aim[0][0]: expected a frame in [-1e+09, 1e+09]"},
      {"  list:\n    - {position: [0, 0, 0], aim: [1, 0]}\n", "controls.list[0].aim[0]: expected a [frame, value] key"},
      {"  list:\n    - {position: [0, 0, 0], lift: {by: degrees, amount: 1}}\n",
       "controls.list[0].lift.by: expected one of fraction, angle"},
      {"  list:\n    - {position: [0, 0, 0], lift: {by: angle, amount: 200}}\n",
       "controls.list[0].lift.amount: expected a number in [-180, 180]"},
      {"  list:\n    - {position: [0, 0, 0], direction: 11}\n",
       "controls.list[0].direction: expected a number in [-10, 10]"},
      {"  list:\n    - {position: [0, 0, 0], random_twist: -5}\n",
       "controls.list[0].random_twist: expected a number in [0, 180]"},
      {"  list:\n    - {position: [0, 0, 0], random_twist: {amount: 5, seed: -1}}\n",
       "controls.list[0].random_twist.seed: expected a whole number"},
      {"  list:\n    - {position: [0, 0, 0], offset: [1, 2]}\n",
       "controls.list[0].offset: expected a list of 3 numbers"},
      {"  list:\n    - {position: [0, 0, 0], offset: {keys: [[1, [0, 0, inf]]]}}\n",
       "controls.list[0].offset.keys[0][1][2]: expected a finite number"},
      {"  list:\n    - {position: [0, 0, 0], map: nowhere.txt}\n",
       "controls.list[0].map: expected an existing file, got \"nowhere.txt\""},
      {"  list:\n    - {name: a, position: [0, 0, 0]}\n    - {name: a, position: [1, 0, 0]}\n",
       "controls.list[1].name: expected a name no other control"},
      {"  list:\n    - {name: a, position: [0, 0, 0], mirror: x}\n    - {name: a.mirror, position: [1, 0, 0]}\n",
       "controls.list[1].name: expected a name no other control"},
      {"  list:\n    - {position: [0, 0, 0], dynamic_blend: {amount: 1, ramp: [[0.5, 0], [0.2, 1]]}}\n",
       "controls.list[0].dynamic_blend.ramp[1][0]: expected t in [0.5, 1] (t sorted from root to tip)"},
      {"  list: {position: [0, 0, 0]}\n", "controls.list: expected a list"},
  };
  for (const Case &c : cases) {
    const std::string extra = c.yaml.find("dynamic_blend") != std::string::npos ? "dynamics: {}\n" : "";
    const std::string message = error_of(write_groom(dir, c.yaml, extra));
    INFO(c.yaml << " -> " << message);
    CHECK(message.find(dir.file("c.groom.yaml") + ":") == 0);
    CHECK(message.find(c.expected) != std::string::npos);
  }
}

TEST_CASE("a vertex map of controls is checked value by value", "[controls][io]") {
  const test::ScratchDir dir("controls_map");
  std::ofstream(dir.file("m.txt")) << "# weights\n0.2\n1.5\n";
  ControlSettings settings;
  ControlDesc c;
  c.vertex_map_path = dir.file("m.txt");
  settings.controls.push_back(c);
  CHECK_THROWS_WITH(io::read_control_maps(settings, 4),
                    Catch::Contains("m.txt:3:1: vertex map value: expected a number in [0, 1], got \"1.5\""));
  std::ofstream(dir.file("m.txt")) << "0.2\nx\n";
  CHECK_THROWS_WITH(io::read_control_maps(settings, 4),
                    Catch::Contains("m.txt:2:1: vertex map value"));
  std::ofstream(dir.file("m.txt")) << "0.2\n0.3\n0.3\n";
  CHECK_THROWS_WITH(io::read_control_maps(settings, 2),
                    Catch::Contains("m.txt:3:1: expected 2 values (one per emitter vertex), got more"));
}
