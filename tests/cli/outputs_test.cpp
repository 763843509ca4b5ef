// Where outputs go, and what a run says about them: command-line paths relative to the current
// folder, a groom file's relative to the groom file (the shipped grooms' inside their own folder),
// a summary at the end of every run, --no-preview, a proxy run that never overwrites the full
// groom's files, and output files that hold no absolute path (the same bytes in any checkout).
#include <catch2/catch.hpp>

#include <sys/stat.h>

#include "cli/cli_fixtures.h"
#include "io/groom_file.h"

using namespace plume::cli_test;

namespace {

/// Copies the folder of a shipped groom (its files, not its outputs) to `to`.
void copy_groom_folder(const std::string &name, const fs::path &to) {
  fs::create_directories(to);
  for (const auto &entry : fs::directory_iterator(fs::path(PLUME_SOURCE_DIR) / "grooms" / name))
    if (entry.is_regular_file()) fs::copy_file(entry.path(), to / entry.path().filename());
    else if (entry.is_directory() && entry.path().filename() != "out")
      fs::copy(entry.path(), to / entry.path().filename(), fs::copy_options::recursive);
}

bool inside(const std::string &path, const fs::path &folder) {
  const std::string prefix = fs::weakly_canonical(folder).string() + "/";
  return fs::weakly_canonical(path).string().rfind(prefix, 0) == 0;
}

}  // namespace

TEST_CASE("a shipped groom's outputs stay in its folder, wherever it is copied and run from", "[cli]") {
  // Every shipped groom names its outputs inside its own folder.
  for (const std::string &groom : shipped_grooms()) {
    INFO(groom);
    const plume::GroomDesc desc = plume::io::read_groom_file(groom);
    const fs::path folder = fs::path(groom).parent_path();
    for (const std::string &pattern : {desc.output.path_pattern, desc.output.preview_pattern, desc.output.vanes_pattern,
                                       desc.dynamics.cache_pattern})
      if (!pattern.empty()) CHECK(inside(pattern, folder));
  }
  // A copy of Sintel, run from a job folder elsewhere: its frames and previews go to the copy's out/,
  // and the summary says so. A proxy of its roots: where outputs go does not depend on the count
  // (the shipped-grooms check regrows every groom at full count).
  ScratchDir scratch("copied_groom");
  copy_groom_folder("sintel", scratch.path / "shots/s010/groom");
  fs::create_directories(scratch.path / "job");
  const std::string groom = scratch / "shots/s010/groom/sintel.groom.yaml";
  const RunResult run = run_plume_command("cd " + quoted(scratch / "job") + " && " + quoted(PLUME_BINARY) +
                                              " regrow ../shots/s010/groom/sintel.groom.yaml --frames 1 --strands 500 --preview-size 64",
                                          scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  const fs::path out = scratch.path / "shots/s010/groom/out";
  // The frame, the USD stage of the groom's frames and its manifest, and the preview (a proxy's names).
  CHECK(files_in(out) == std::vector<std::string>{(out / "hair_proxy500.0001.usda").string(), (out / "hair_proxy500.manifest.usda").string(),
                                                  (out / "hair_proxy500.usda").string(), (out / "preview_proxy500.0001.png").string()});
  CHECK(files_in(scratch.path / "job").empty());
  INFO(run.out);
  const std::string size = std::to_string(fs::file_size(out / "hair_proxy500.0001.usda"));
  CHECK(run.out.rfind("plume regrow: frame 1 (1) in ", 0) == 0);
  CHECK(run.out.find("  strands   " + (out / "hair_proxy500.####.usda").string() + ": 1 file, " + size + " bytes") !=
        std::string::npos);
  CHECK(run.out.find("  previews  " + (out / "preview_proxy500.####.png").string() + ": 1 file, ") != std::string::npos);
  // Command-line paths are relative to the current folder.
  const RunResult here = run_plume_command("cd " + quoted(scratch / "job") + " && " + quoted(PLUME_BINARY) +
                                               " regrow " + quoted(groom) +
                                               " --frames 1 --strands 20 --out h/h.####.hair --preview p/p.png",
                                           scratch);
  REQUIRE(here.exit_code == 0);
  CHECK(fs::exists(scratch / "job/h/h.0001.hair"));
  CHECK(fs::exists(scratch / "job/p/p.png"));
  CHECK(here.out.find((scratch.path / "job/h/h.####.hair").string() + ": 1 file") != std::string::npos);
}

TEST_CASE("the summary counts every file and byte a run wrote: regrow, simulate, preview and view", "[cli]") {
  ScratchDir scratch("summary");
  const std::string groom = write_sintel_groom(scratch, "g", "dynamics: {enabled: true}\n");
  RunResult run = run_plume("simulate " + quoted(groom) + " --frames 1-4 --cache " + quoted(scratch / "c/g.####.hair") +
                                " --preview " + quoted(scratch / "c/p.####.png") + " --preview-every 2 --preview-size 32",
                            scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  uint64_t cache_bytes = 0, preview_bytes = 0;
  for (const std::string &file : files_in(scratch.path / "c"))
    (file.ends_with(".png") ? preview_bytes : cache_bytes) += fs::file_size(file);
  INFO(run.out);
  CHECK(run.out.rfind("plume simulate: frames 1-4 (4) in ", 0) == 0);
  CHECK(run.out.find("guide cache  " + (scratch.path / "c/g.####.hair").string() + ": 4 files, " +
                     std::to_string(cache_bytes) + " bytes") != std::string::npos);
  CHECK(run.out.find("previews     " + (scratch.path / "c/p.####.png").string() + ": 2 files, " +
                     std::to_string(preview_bytes) + " bytes") != std::string::npos);
  run = run_plume("regrow " + quoted(groom) + " --frames 1-4x3 --strands 30 --out " + quoted(scratch / "r/h.####.ply") +
                      " --guides-cache " + quoted(scratch / "c/g.####.hair"),
                  scratch);
  REQUIRE(run.exit_code == 0);
  uint64_t bytes = 0;
  for (const std::string &file : files_in(scratch.path / "r")) bytes += fs::file_size(file);
  CHECK(files_in(scratch.path / "r").size() == 2);
  CHECK(run.out.rfind("plume regrow: frames 1-4:3 (2) in ", 0) == 0);
  CHECK(run.out.find(": 2 files, " + std::to_string(bytes) + " bytes") != std::string::npos);
  CHECK(run.out.find("  previews  none\n") != std::string::npos);
  // preview and view, one file each.
  run = run_plume("preview " + quoted(groom) + " --frame 2 --strands 30 --size 32 --out " + quoted(scratch / "pv/p.####.png"),
                  scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(run.out.rfind("plume preview: frame 2 (1) in ", 0) == 0);
  CHECK(run.out.find("  preview  " + (scratch.path / "pv/p.####.png").string() + ": 1 file, " +
                     std::to_string(fs::file_size(scratch / "pv/p.0002.png")) + " bytes") != std::string::npos);
  run = run_plume("view " + quoted(groom) + " --frames 1-2 --strands 20 --out " + quoted(scratch / "pv/v.html"), scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(run.out.rfind("plume view: frames 1-2 (2) in ", 0) == 0);
  CHECK(run.out.find("  page  " + (scratch.path / "pv/v.html").string() + ": 1 file, " +
                     std::to_string(fs::file_size(scratch / "pv/v.html")) + " bytes") != std::string::npos);
}

TEST_CASE("--no-preview writes no preview; --preview \"\" and --out \"\" are errors, not the groom's paths", "[cli]") {
  ScratchDir scratch("no_preview");
  const std::string groom =
      write_sintel_groom(scratch, "g", "output: {path: out/h.####.hair, preview: out/p.####.png, preview_size: 32}\n");
  RunResult run = run_plume("regrow " + quoted(groom) + " --frames 1-2 --no-preview", scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(files_in(scratch.path / "out") ==
        std::vector<std::string>{scratch / "out/h.0001.hair", scratch / "out/h.0002.hair"});
  CHECK(run.out.find("previews  none") != std::string::npos);
  fs::remove_all(scratch.path / "out");
  for (const std::string args : {"--preview ''", "--out ''", "--preview '' --no-preview", "--frames ''"}) {
    INFO(args);
    run = run_plume("regrow " + quoted(groom) + " --frames 1 --strands 20 " + args, scratch);
    CHECK(run.exit_code == 2);
    CHECK(run.err.rfind("plume: error: --", 0) == 0);
    CHECK_FALSE(fs::exists(scratch / "out"));
  }
  CHECK(run_plume("regrow " + quoted(groom) + " --frames 1 --preview ''", scratch).err.find("--no-preview") !=
        std::string::npos);
  // simulate's --cache "" likewise.
  const std::string dynamic = write_sintel_groom(scratch, "d", "dynamics: {enabled: true, cache: c/g.####.hair}\n");
  run = run_plume("simulate " + quoted(dynamic) + " --frames 1 --cache ''", scratch);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("--cache") != std::string::npos);
  CHECK_FALSE(fs::exists(scratch / "c"));
}

TEST_CASE("a proxy run (--strands) never overwrites the full groom's outputs unless given them", "[cli]") {
  ScratchDir scratch("proxy_outputs");
  const std::string groom = write_sintel_groom(
      scratch, "g",
      "output: {path: out/h.####.usda, preview: out/p.####.png, preview_size: 32, preview_every: 1, frames: 1-2}\n");
  RunResult run = run_plume("regrow " + quoted(groom), scratch);
  REQUIRE(run.exit_code == 0);
  const std::vector<std::string> full = files_in(scratch.path / "out");
  REQUIRE(full.size() == 6);  // 2 frames, 2 previews, the USD stage and its manifest
  std::vector<std::string> full_bytes;
  for (const std::string &file : full) full_bytes.push_back(read_text(file));

  run = run_plume("regrow " + quoted(groom) + " --strands 50", scratch);
  REQUIRE(run.exit_code == 0);
  INFO(run.out);
  for (size_t i = 0; i < full.size(); ++i) CHECK(read_text(full[i]) == full_bytes[i]);
  for (const std::string name : {"h_proxy50.0001.usda", "h_proxy50.0002.usda", "p_proxy50.0001.png", "p_proxy50.0002.png"})
    CHECK(fs::exists(scratch / ("out/" + name)));
  CHECK(run.out.find((scratch.path / "out/h_proxy50.####.usda").string() + ": 2 files") != std::string::npos);
  CHECK(run.out.find((scratch.path / "out/p_proxy50.####.png").string() + ": 2 files") != std::string::npos);
  // Asked for: an --out or --preview of the command line is written as given.
  run = run_plume("regrow " + quoted(groom) + " --strands 50 --frames 1 --out " + quoted(scratch / "out/h.####.usda") +
                      " --no-preview",
                  scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(read_text(full[0]) != full_bytes[0]);
  CHECK(read_text(full[4]) == full_bytes[4]);  // p.0001.png: no preview this time
  CHECK(files_in(scratch.path / "out").size() == 12);  // and the proxy's frames, previews, stage and manifest
  // Patterns without a frame field, or with $F4, in a sub-folder: the name changes, not the folder.
  const std::string other = write_sintel_groom(
      scratch, "other", "output: {path: sub/h.usda, preview: sub/p.$F4.png, preview_size: 32, frames: 3}\n");
  run = run_plume("regrow " + quoted(other) + " --strands 7", scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(files_in(scratch.path / "sub") ==
        std::vector<std::string>{scratch / "sub/h_proxy7.usda", scratch / "sub/p_proxy7.0003.png"});
}

TEST_CASE("two copies of a groom in different folders write the same bytes, hair and feathers", "[cli]") {
  ScratchDir scratch("same_bytes");
  for (const std::string copy : {"a", "b/deeper/still"}) {
    copy_groom_folder("sintel", scratch.path / copy / "sintel");
    copy_groom_folder("bird", scratch.path / copy / "bird");
  }
  for (const std::string ext : {"usda", "hair", "ply", "obj"}) {
    INFO(ext);
    for (const std::string copy : {"a", "b/deeper/still"}) {
      const RunResult run = run_plume("regrow " + quoted(scratch / (copy + "/sintel/sintel.groom.yaml")) +
                                          " --frames 2 --strands 200 --no-preview --out " +
                                          quoted(scratch / (copy + "/out/hair.####." + ext)),
                                      scratch);
      INFO(run.err);
      REQUIRE(run.exit_code == 0);
    }
    const std::string a = read_text(scratch / ("a/out/hair.0002." + ext));
    CHECK(a.size() > 1000);
    CHECK(a == read_text(scratch / ("b/deeper/still/out/hair.0002." + ext)));
    CHECK(a.find(scratch.path.string()) == std::string::npos);
    if (ext != "hair") CHECK(a.find("sintel.groom.yaml") != std::string::npos);  // the groom's name instead
  }
  for (const std::string copy : {"a", "b/deeper/still"}) {
    const RunResult run = run_plume("regrow " + quoted(scratch / (copy + "/bird/bird.groom.yaml")) +
                                        " --frames 1 --strands 20 --no-preview --out " +
                                        quoted(scratch / (copy + "/out/f.####.usda")) + " --vanes " +
                                        quoted(scratch / (copy + "/out/v.####.obj")),
                                    scratch);
    INFO(run.err);
    REQUIRE(run.exit_code == 0);
  }
  // The 3D view pages, hair and feathers.
  for (const std::string copy : {"a", "b/deeper/still"})
    for (const std::string groom : {"sintel", "bird"}) {
      const RunResult run = run_plume("view " + quoted(scratch / (copy + "/" + groom + "/" + groom + ".groom.yaml")) +
                                          " --frames 1 --strands 20 --out " +
                                          quoted(scratch / (copy + "/out/" + groom + ".html")),
                                      scratch);
      INFO(run.err);
      REQUIRE(run.exit_code == 0);
    }
  for (const std::string name : {"f.0001.usda", "v.0001.obj", "sintel.html", "bird.html"}) {
    const std::string a = read_text(scratch / ("a/out/" + name));
    CHECK(a.size() > 1000);
    CHECK(a == read_text(scratch / ("b/deeper/still/out/" + name)));
    CHECK(a.find(scratch.path.string()) == std::string::npos);
  }
}
