// `plume help [COMMAND]` and `plume version`, the exit codes every `--help` lists, and the form
// of command-line errors (prefixed "plume: error:" like every other error).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace plume {

/// The exit codes, as `--help` lists them under every command.
std::string exit_codes_text();
/// Sets what every command's help ends with (the exit codes) and how parse errors read:
/// "plume: error: <what CLI11 found> (plume help COMMAND lists the options)". Call before adding
/// subcommands, which copy both.
void set_help_conventions(CLI::App &app);
/// Adds `plume help [COMMAND]`: the help of the program, or of a command (as `plume COMMAND
/// --help`), on stdout. An unknown command is bad input (exit 2).
void add_help_command(CLI::App &app);
/// Adds `plume version`: version_text() on stdout (as `plume --version`).
void add_version_command(CLI::App &app);
/// True when the command line chose `help` or `version`, which need no threads.
bool chose_help_or_version(const CLI::App &app);

}  // namespace plume
