// The shadesim program's subcommands. Each is a Command in its own file of sim/cli/, listed
// once in commands.cpp; main.cpp only wires them to CLI11 and reports their errors.
// Exit status of run(): kExitOk, kExitFailed (a check failed) or kExitBadInput (cli/options.h;
// cli::run prints "shadesim <command>: error: ..." for an exception and returns kExitBadInput).
#pragma once

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/options.h"
#include "config/registry.h"

namespace shd::cli {

class Command {
 public:
  virtual ~Command() = default;
  virtual void add(CLI::App& app) = 0;  // the options
  virtual int run(const CLI::App& app) = 0;
};

struct CommandInfo {
  const char* name;
  const char* help;
  std::unique_ptr<Command> (*make)();
};

// Every subcommand, in the order `shadesim --help` lists them.
const std::vector<CommandInfo>& commands();

// The command line of this run as typed, each argument shell-quoted where it needs it: what a
// report records of how it was made ("" outside cli::run).
const std::string& commandLine();

// A configuration option (registry name or JSON file). Errors are ArgError: an unknown name
// names the option, an error in a file "configuration file <path>: <member>: ...".
SpecUnitConfig specConfigArg(const std::string& option, const std::string& arg);
SpanUnitConfig spanConfigArg(const std::string& option, const std::string& arg);
// The directory `dir` that `option` `arg` names: true if it exists, false if it is new and its
// parent exists (it is made later). ArgError otherwise; `why` follows "not a directory".
bool existingOrNewDir(const char* option, const std::string& arg, const std::filesystem::path& dir, const char* why);

// "name | name | ... or a JSON file": the registry's names of a unit, for help texts.
std::string configChoices(const std::string& unit);

}  // namespace shd::cli
