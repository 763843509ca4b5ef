// AtomicFile: a file appears whole on commit, and nothing is left when the writer throws.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "groom/error.h"
#include "io/atomic_file.h"
#include "io/strand_file.h"
#include "scratch_dir.h"

TEST_CASE("AtomicFile creates missing directories and renames onto the path only on commit", "[io]") {
  plume::test::ScratchDir dir("atomic");
  const std::string path = dir.file("a/b/out.txt");
  {
    plume::io::AtomicFile file(path);
    file.write("hello");
    CHECK(std::filesystem::exists(file.temp_path()));
    CHECK_FALSE(std::filesystem::exists(path));
    file.commit();
    CHECK_FALSE(std::filesystem::exists(file.temp_path()));
  }
  std::ifstream in(path);
  std::string text;
  in >> text;
  CHECK(text == "hello");
}

TEST_CASE("AtomicFile leaves no file, temporary or final, when the writer throws", "[io]") {
  plume::test::ScratchDir dir("atomic_throw");
  const std::string path = dir.file("out.usda");
  std::ofstream(path) << "previous";
  try {
    plume::io::AtomicFile file(path);
    file.write("half of a fi");
    throw std::runtime_error("writer failed");
  } catch (const std::runtime_error &) {
  }
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto &entry : std::filesystem::directory_iterator(dir.path())) ++entries;
  CHECK(entries == 1);  // only the previous, untouched file
  std::ifstream in(path);
  std::string text;
  in >> text;
  CHECK(text == "previous");
}

TEST_CASE("a strand writer that fails midway leaves no output file", "[io]") {
  plume::test::ScratchDir dir("atomic_writer");
  plume::StrandSet strands;
  strands.append(std::vector<Eigen::Vector3f>{{0, 0, 0}, {0, 1, 0}}, std::numeric_limits<uint64_t>::max());
  CHECK_THROWS_AS(plume::io::write_strands(dir.file("ids.usda"), strands, {}), plume::InputError);
  CHECK(std::filesystem::is_empty(dir.path()));
}

TEST_CASE("AtomicFile names the file when it cannot be created", "[io]") {
  plume::test::ScratchDir dir("atomic_fail");
  std::ofstream(dir.file("plain")) << "x";
  CHECK_THROWS_WITH(plume::io::AtomicFile(dir.file("plain/sub/out.hair")),
                    Catch::Contains("plain/sub/out.hair") && Catch::Contains("cannot create"));
}
