// What the readers' libFuzzer targets share: each input becomes a file the reader opens by name,
// and the oracle: only InputError may leave a reader, and whatever it returns is valid (finite,
// within the scene bound, every strand of at least 2 points). Any other outcome aborts, which
// libFuzzer records as a finding with the input that caused it.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "groom/error.h"
#include "groom/groom_desc.h"
#include "groom/mesh.h"
#include "groom/strand_set.h"

namespace plume::fuzz {

/// A folder of this process for the inputs (in /dev/shm when it exists: no disk writes per input),
/// made on first use and removed at exit. `seed_files` are copied into it once (files a groom may
/// name, from the folder of tests/data the groom seeds come from).
const std::string &work_folder(const std::vector<std::string> &seed_files = {});

/// Writes `data` to `name` in the work folder and returns its path.
std::string write_input(const uint8_t *data, size_t size, const std::string &name);

/// Prints `what` and aborts: libFuzzer keeps the input as a crash.
[[noreturn]] void finding(const std::string &what);

/// Runs `read`; an InputError is the expected refusal of bad input, anything else a finding.
template <class Read>
void only_input_errors(const Read &read) {
  try {
    read();
  } catch (const InputError &) {
  } catch (const std::exception &error) {
    finding(std::string("an exception other than InputError left the reader: ") + error.what());
  } catch (...) {
    finding("a non-standard exception left the reader");
  }
}

/// The promises on what a reader returns; each failure is a finding.
void check_strands(const StrandSet &strands);
void check_mesh(const Mesh &mesh);
void check_points(const std::vector<Eigen::Vector3f> &points);
void check_groom(const GroomDesc &groom);

}  // namespace plume::fuzz
