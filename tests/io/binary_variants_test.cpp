// Binary files written byte by byte as other tools write them: .hair without a segments array,
// .hair with bytes after its arrays, binary PLY with a list element and per-vertex strand ids.
#include <catch2/catch.hpp>

#include <cstring>
#include <fstream>
#include <string>

#include "groom/error.h"
#include "io/strand_file.h"
#include "scratch_dir.h"

namespace {

template <class T>
void put(std::string &bytes, T value) {
  bytes.append(reinterpret_cast<const char *>(&value), sizeof(T));
}

/// A .hair header: hair count, point count, arrays bits, default segments, default thickness.
std::string hair_header(uint32_t hairs, uint32_t points, uint32_t arrays, uint32_t default_segments) {
  std::string bytes = "HAIR";
  for (uint32_t v : {hairs, points, arrays, default_segments}) put(bytes, v);
  for (float v : {0.5f, 1.0f, 0.0f, 0.0f, 0.0f}) put(bytes, v);
  bytes.resize(128, '\0');
  return bytes;
}

void write_bytes(const std::string &path, const std::string &bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

}  // namespace

TEST_CASE("a .hair file without a segments array uses the default segment count and keeps thickness", "[io]") {
  plume::test::ScratchDir dir("hair_default_segments");
  std::string bytes = hair_header(2, 6, 2 | 4, 2);  // points + thickness, 2 segments per strand
  for (int p = 0; p < 6; ++p)
    for (float v : {float(p), 2.0f * float(p), -float(p)}) put(bytes, v);
  for (int p = 0; p < 6; ++p) put(bytes, 0.1f * float(p + 1));
  write_bytes(dir.file("d.hair"), bytes);
  const plume::StrandSet strands = plume::io::read_strands(dir.file("d.hair"));
  CHECK(strands.offsets == std::vector<int64_t>{0, 3, 6});
  CHECK(strands.positions[4] == Eigen::Vector3f(4, 8, -4));
  REQUIRE(strands.widths.size() == 6);
  CHECK(strands.widths[5] == 0.1f * 6.0f);

  SECTION("a default segment count that disagrees with the point count is refused") {
    std::string wrong = bytes;
    const uint32_t three = 3;
    std::memcpy(wrong.data() + 16, &three, 4);
    write_bytes(dir.file("wrong.hair"), wrong);
    CHECK_THROWS_WITH(plume::io::read_strands(dir.file("wrong.hair")),
                      Catch::Contains("wrong.hair@byte 16: segments: expected to add up to the point count 6") &&
                          Catch::Contains("got 8"));
  }
  SECTION("bytes after the announced arrays are refused") {
    write_bytes(dir.file("long.hair"), bytes + "junk");
    CHECK_THROWS_WITH(plume::io::read_strands(dir.file("long.hair")),
                      Catch::Contains("long.hair@byte 224: expected the file to end here") && Catch::Contains("got 4 more bytes"));
  }
}

TEST_CASE("a binary PLY with a list element to skip and per-vertex curve ids reads its strands", "[io]") {
  plume::test::ScratchDir dir("ply_binary_ids");
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nproperty ushort curve\nelement face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n";
  for (int v = 0; v < 4; ++v) {
    for (float c : {float(v), 1.0f, 2.0f}) put(bytes, c);
    put(bytes, uint8_t(200));
    put(bytes, uint16_t(v < 2 ? 4 : 9));
  }
  put(bytes, uint8_t(3));
  for (int32_t i : {0, 1, 2}) put(bytes, i);
  write_bytes(dir.file("b.ply"), bytes);
  const plume::StrandSet strands = plume::io::read_strands(dir.file("b.ply"));
  CHECK(strands.offsets == std::vector<int64_t>{0, 2, 4});
  CHECK(strands.positions[3] == Eigen::Vector3f(3, 1, 2));

  SECTION("a list that runs past the end of the file is refused at its byte offset") {
    std::string cut = bytes.substr(0, bytes.size() - 8);
    write_bytes(dir.file("cut.ply"), cut);
    CHECK_THROWS_WITH(plume::io::read_strands(dir.file("cut.ply")),
                      Catch::Contains("cut.ply@byte") && Catch::Contains("element face list vertex_indices: expected 3 x 4 bytes, file ends after 4"));
  }
}
