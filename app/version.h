// What `plume version` and `plume --version` print: the release, the commit the program was built
// from and how it was built, for bug reports and for checking what a farm node runs.
#pragma once

#include <string>

namespace plume {

/// "plume 0.1.0 (commit 0123456789ab, Release build, AVX2)": the project version, the source
/// commit (cmake/PlumeBuildInfo.cmake: git, else a release archive's, else "unknown"; "-dirty"
/// when tracked files differed from it), the CMake build type and the instruction set.
std::string version_text();

}  // namespace plume
