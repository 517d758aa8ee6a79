// The list of shadesim's subcommands: one row each, in the order of `shadesim --help`.
#include "cli/command.h"

namespace shd::cli {

std::unique_ptr<Command> makePromCmd();
std::unique_ptr<Command> makeCosimCmd();
std::unique_ptr<Command> makeSpecErrorCmd();
std::unique_ptr<Command> makeSpanCyclesCmd();
std::unique_ptr<Command> makeRenderCmd();
std::unique_ptr<Command> makeVectorsCmd();
std::unique_ptr<Command> makeReplayCmd();
std::unique_ptr<Command> makeConfigsCmd();

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
  };
  return all;
}

}  // namespace shd::cli
