#include "app/cmd_help.h"

#include <cstdio>
#include <memory>

#include "app/version.h"
#include "groom/error.h"

namespace plume {

std::string exit_codes_text() {
  return "Exit codes:\n"
         "  0  done\n"
         "  1  internal failure (a bug: please report the message)\n"
         "  2  bad input: a missing or malformed file, option, frame range or output path (the message names it);\n"
         "     nothing is written\n"
         "  3  plume check --strict found a violation\n";
}

void set_help_conventions(CLI::App &app) {
  app.footer(exit_codes_text());
  app.failure_message([](const CLI::App *failed, const CLI::Error &error) {
    // The command the error is about, for the pointer to its help.
    std::string command;
    for (const CLI::App *sub : failed->get_subcommands()) command = " " + sub->get_name();
    return "plume: error: " + std::string(error.what()) + " (plume help" + command + " lists the options)\n";
  });
}

void add_help_command(CLI::App &app) {
  auto topic = std::make_shared<std::string>();
  CLI::App *cmd = app.add_subcommand("help", "Print the help of plume, or of a command: plume help regrow.");
  cmd->add_option("command", *topic, "A command (regrow, simulate, preview, view, info, check, version)");
  cmd->callback([&app, topic] {
    if (topic->empty()) {
      // app.help() would show the help of the chosen command, `help` itself.
      std::fputs(app.get_formatter()->make_help(&app, app.get_name(), CLI::AppFormatMode::Normal).c_str(), stdout);
      return;
    }
    for (const CLI::App *sub : app.get_subcommands([](const CLI::App *) { return true; }))
      if (sub->get_name() == *topic) {
        std::fputs(sub->help(app.get_name()).c_str(), stdout);
        return;
      }
    std::string names;
    for (const CLI::App *sub : app.get_subcommands([](const CLI::App *) { return true; }))
      names += (names.empty() ? "" : ", ") + sub->get_name();
    throw InputError("help: no command \"" + *topic + "\"; the commands are " + names);
  });
}

void add_version_command(CLI::App &app) {
  CLI::App *cmd = app.add_subcommand("version", "Print the version, the commit it was built from and the build type.");
  cmd->callback([] { std::printf("%s\n", version_text().c_str()); });
}

bool chose_help_or_version(const CLI::App &app) { return app.got_subcommand("help") || app.got_subcommand("version"); }

}  // namespace plume
