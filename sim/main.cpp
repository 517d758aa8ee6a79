// shadesim: the command-line program. The subcommands are in sim/cli/, one file each, listed in
// sim/cli/commands.cpp; this file wires them to CLI11. Every failure prints
// "shadesim <command>: error: ..." naming the argument and exits non-zero; files are written
// atomically, so a failed run leaves no partial output.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "cli/command.h"

int main(int argc, char** argv) {
  using namespace shd::cli;
  CLI::App app{fmt::format("shadesim {}: cycle-accurate models and RTL of the shading hardware", SHD_VERSION)};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("shadesim ") + SHD_VERSION);
  std::vector<std::pair<CLI::App*, std::unique_ptr<Command>>> subs;
  for (const CommandInfo& c : commands()) {
    CLI::App* sub = app.add_subcommand(c.name, c.help);
    subs.emplace_back(sub, c.make());
    subs.back().second->add(*sub);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (auto& [sub, cmd] : subs) {
    if (!sub->parsed()) continue;
    try {
      return cmd->run(*sub);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "shadesim %s: error: %s\n", sub->get_name().c_str(), e.what());
      return 2;
    }
  }
  return 2;
}
