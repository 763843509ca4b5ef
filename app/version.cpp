#include "app/version.h"

// Written at build time by cmake/PlumeBuildInfo.cmake (build/app/build_info.cpp).
extern const char *const plume_source_commit;

namespace plume {

std::string version_text() {
  const std::string build_type = PLUME_BUILD_TYPE;
#if defined(PLUME_REQUIRES_AVX2)
  const char *instructions = "AVX2";
#else
  const char *instructions = "baseline instruction set";
#endif
  return std::string("plume ") + PLUME_VERSION + " (commit " + plume_source_commit + ", " +
         (build_type.empty() ? std::string("no build type") : build_type + " build") + ", " + instructions + ")";
}

}  // namespace plume
