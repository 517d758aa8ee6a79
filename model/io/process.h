// Running another program and reading what it says: the SystemC testbench's replay of a failing
// case, a sweep's synthesis by yosys.
#pragma once

#include <string>
#include <vector>

namespace shd {

// Runs argv (argv[0] looked up in PATH when it has no '/'), returns its exit status and what it
// wrote on stdout and stderr (read together with poll, so that neither pipe can fill and block
// it). -1 with `error` set when it could not start or did not exit normally ("<argv[0]> was
// killed by signal N (name)").
int runProcess(const std::vector<std::string>& argv, std::string& out, std::string& err, std::string& error);

}  // namespace shd
