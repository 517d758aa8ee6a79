// shadesim: the command-line program. The subcommands are in sim/cli/, one file each, listed in
// sim/cli/commands.cpp with the wiring to CLI11.
#include "cli/run.h"

int main(int argc, char** argv) { return shd::cli::run(argc, argv); }
