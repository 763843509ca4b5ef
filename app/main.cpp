// The `plume` command: parses the command line (CLI11), runs the chosen subcommand and maps errors
// to exit codes: 0 done, 2 bad input (InputError or a command-line error), 1 internal failure,
// 3 `plume check --strict` found a violation.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "app/commands.h"
#include "groom/error.h"

int main(int argc, char **argv) {
  CLI::App app{"Plume: regrows dense hair from guide strands on an emitter mesh, frame by frame."};
  app.set_version_flag("--version", std::string("plume ") + PLUME_VERSION);
  app.require_subcommand(1);
  int exit_code = 0;
  plume::add_regrow_command(app, exit_code);
  plume::add_simulate_command(app, exit_code);
  plume::add_preview_command(app, exit_code);
  plume::add_info_command(app, exit_code);
  plume::add_check_command(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &e) {
    // --help and --version arrive here as "successes"; every other parse error is bad input.
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const plume::InputError &e) {
    std::fprintf(stderr, "plume: error: %s\n", e.what());
    return 2;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "plume: internal error: %s\n", e.what());
    return 1;
  } catch (...) {
    std::fprintf(stderr, "plume: internal error: unknown exception\n");
    return 1;
  }
  return exit_code;
}
