// The `plume` command: parses the command line (CLI11), runs the chosen subcommand and maps errors
// to exit codes: 0 done, 2 bad input (InputError or a command-line error), 1 internal failure,
// 3 `plume check --strict` found a violation. SIGTERM, SIGINT and SIGHUP remove the temporary files
// of outputs being written before the process dies of the signal.
#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <exception>

#include "app/cmd_help.h"
#include "app/commands.h"
#include "app/version.h"
#include "groom/error.h"
#include "io/atomic_file.h"

namespace {

/// Runs on the thread that received the signal, with the action already reset to the default
/// (SA_RESETHAND): removes the partial outputs, then re-raises so that the signal ends the process
/// on return and the parent (a shell, `timeout`, a batch scheduler) still sees "killed by signal".
void remove_temp_files_and_reraise(int signal_number) {
  plume::io::remove_open_temp_files();
  std::raise(signal_number);
}

/// Installs the handler for the signals that stop a task (`timeout`, batch time limits and
/// preemption send SIGTERM, Ctrl-C SIGINT, a closed terminal SIGHUP). A signal the parent set to be
/// ignored (`nohup`, background jobs) stays ignored.
void remove_temp_files_on_stop_signals() {
  struct sigaction action = {};
  action.sa_handler = remove_temp_files_and_reraise;
  action.sa_flags = SA_RESETHAND;
  sigemptyset(&action.sa_mask);
  for (const int signal_number : {SIGTERM, SIGINT, SIGHUP}) sigaddset(&action.sa_mask, signal_number);
  for (const int signal_number : {SIGTERM, SIGINT, SIGHUP}) {
    struct sigaction previous = {};
    sigaction(signal_number, nullptr, &previous);
    if (previous.sa_handler != SIG_IGN) sigaction(signal_number, &action, nullptr);
  }
}

}  // namespace

int main(int argc, char **argv) {
  remove_temp_files_on_stop_signals();
  CLI::App app{"Plume: regrows dense hair from guide strands on an emitter mesh, frame by frame.", "plume"};
  app.set_version_flag("--version", plume::version_text());
  app.require_subcommand(1);
  plume::set_help_conventions(app);  // before the subcommands, which copy it
  int exit_code = 0;
  plume::add_regrow_command(app, exit_code);
  plume::add_simulate_command(app, exit_code);
  plume::add_preview_command(app, exit_code);
  plume::add_info_command(app, exit_code);
  plume::add_check_command(app, exit_code);
  plume::add_view_command(app, exit_code);
  plume::add_help_command(app);
  plume::add_version_command(app);
  // Before any command runs (and after --help and --version, which need no threads).
  app.parse_complete_callback([&app] {
    if (!plume::chose_help_or_version(app)) plume::check_omp_num_threads();
  });
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
