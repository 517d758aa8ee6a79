// The list of shadesim's subcommands (one row each, in the order of `shadesim --help`) and the
// program wired to CLI11: every failure prints "shadesim <command>: error: ..." naming the
// argument and exits with kExitBadInput (cli/options.h); files are written as one set, so a
// failed run leaves no partial output (io/files.h).
#include <cstdio>
#include <exception>
#include <new>

#include <fmt/format.h>

#include "cli/command.h"
#include "cli/run.h"
#include "io/files.h"

namespace shd::cli {

std::unique_ptr<Command> makePromCmd();
std::unique_ptr<Command> makeCosimCmd();
std::unique_ptr<Command> makeSpecErrorCmd();
std::unique_ptr<Command> makeSpanCyclesCmd();
std::unique_ptr<Command> makeRenderCmd();
std::unique_ptr<Command> makeVectorsCmd();
std::unique_ptr<Command> makeReplayCmd();
std::unique_ptr<Command> makeConfigsCmd();
std::unique_ptr<Command> makeSweepCmd();
std::unique_ptr<Command> makeSweepMergeCmd();
std::unique_ptr<Command> makeReportCmd();
std::unique_ptr<Command> makePruneCmd();

namespace {

std::string command_line;  // commandLine(): set once by run()

// An argument as a POSIX shell reads it back: bare when it holds only safe characters, else in
// single quotes (a quote inside written '\'').
std::string shellQuoted(const std::string& a) {
  const bool safe = !a.empty() && a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                                      "_-+=.,:/@%") == std::string::npos;
  if (safe) return a;
  std::string q = "'";
  for (char c : a) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

const std::string& commandLine() { return command_line; }

const std::vector<CommandInfo>& commands() {
  static const std::vector<CommandInfo> all = {
      {"prom", "write the coefficient PROM of the specular unit", makePromCmd},
      {"cosim", "run the verilated RTL against the golden model", makeCosimCmd},
      {"spec-error", "error report of the specular unit", makeSpecErrorCmd},
      {"render", "render a scene with a shading method (and the RTL in the loop)", makeRenderCmd},
      {"span-cycles", "cycles of the span unit per mode, and the paper's speed-up claims", makeSpanCyclesCmd},
      {"vectors", "write a vector file (inputs and the golden model's outputs, cycle by cycle)", makeVectorsCmd},
      {"replay", "replay a vector file on the verilated RTL, comparing every cycle", makeReplayCmd},
      {"configs", "list the unit configurations built in, and which have a verilated model", makeConfigsCmd},
      {"sweep", "evaluate the specular unit over a grid of its parameters (error, latency, PROM size, area)", makeSweepCmd},
      {"sweep-merge", "join the shard directories of one sweep", makeSweepMergeCmd},
      {"report", "what each shading method and lobe costs and buys on a scene: error, time, cycles, area",
       makeReportCmd},
      {"prune", "the smallest units one scene needs: its shininess values, lane mode, what it leaves unused", makePruneCmd},
  };
  return all;
}

int run(int argc, char** argv) {
  command_line = "shadesim";
  for (int i = 1; i < argc; ++i) command_line += " " + shellQuoted(argv[i]);
  CLI::App app{fmt::format("shadesim {}: cycle-accurate models and RTL of the shading hardware", SHD_VERSION)};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("shadesim ") + SHD_VERSION);
  std::vector<std::pair<CLI::App*, std::unique_ptr<Command>>> subs;
  for (const CommandInfo& c : commands()) {
    CLI::App* sub = app.add_subcommand(c.name, c.help);
    subs.emplace_back(sub, c.make());
    subs.back().second->add(*sub);
  }
  // A first word that is no command is named (CLI11 would only say that a command is missing).
  if (argc > 1 && argv[1][0] != '-') {
    bool known = false;
    std::string names;
    for (const CommandInfo& c : commands()) {
      known = known || c.name == std::string(argv[1]);
      names += (names.empty() ? "" : ", ") + std::string(c.name);
    }
    if (!known) {
      std::fprintf(stderr, "shadesim: error: unknown command '%s' (commands: %s)\n", argv[1], names.c_str());
      return kExitBadInput;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::string who = "shadesim";
    for (const auto& s : subs)
      if (s.first->parsed()) who += " " + s.first->get_name();
    return parseErrorExit(app, e, who);
  }
  for (auto& [sub, cmd] : subs) {
    if (!sub->parsed()) continue;
    try {
      const RunInputs inputs;  // the files this run reads may not be its outputs (io/files.h)
      return cmd->run(*sub);
    } catch (const std::bad_alloc&) {
      std::fprintf(stderr, "shadesim %s: error: out of memory\n", sub->get_name().c_str());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "shadesim %s: error: %s\n", sub->get_name().c_str(), e.what());
    }
    return kExitBadInput;
  }
  return kExitBadInput;
}

}  // namespace shd::cli
