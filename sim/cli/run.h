// The shadesim program (sim/cli/commands.cpp): parses argv and runs the subcommand; returns the
// exit status.
#pragma once

namespace shd::cli {

int run(int argc, char** argv);

}  // namespace shd::cli
