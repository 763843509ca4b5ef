// The `plume` command: parses the command line (CLI11) and maps errors to exit codes
// (0 done, 2 bad input, 1 internal failure).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "groom/error.h"

int main(int argc, char **argv) {
  CLI::App app{"Plume: regrows dense hair from guide strands, frame by frame."};
  app.set_version_flag("--version", std::string("plume ") + PLUME_VERSION);
  app.require_subcommand(1);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  return 0;
}
