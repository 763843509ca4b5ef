// A Plume built for AVX2 (PLUME_CPU, see CMakeLists.txt) stops with a message on a processor
// without it, before any of its code runs, instead of dying of an illegal instruction. This file is
// compiled without AVX and added to every program that links plume_groom.
#include <unistd.h>

namespace {

#if defined(PLUME_REQUIRES_AVX2) && defined(__x86_64__)
[[gnu::constructor(101)]] void refuse_a_processor_without_avx2() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2")) return;
  static const char message[] =
      "plume: this build of Plume uses AVX2 instructions, which this processor lacks; build it with "
      "-DPLUME_CPU=baseline to run here\n";
  if (write(STDERR_FILENO, message, sizeof message - 1) < 0) {
    // Nothing more can be said; the exit status tells.
  }
  _exit(3);
}
#endif

}  // namespace
