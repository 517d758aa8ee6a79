// The failing case a run saved (sc_run.h, ScFailCase), replayed alone in a child process of this
// program: a SystemC simulation elaborates once per process, so the waveform of the case alone
// comes from a second run,
//   shadesim_systemc --unit U --config C --vector-file <fail.vec> --fst <fail.fst> --json --quiet --no-fail-save
// which also checks that the case reproduces: it must fail (exit status 1) at the file's last
// cycle and not before.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sc_run.h"

namespace shd {

struct ScFailReplay {
  std::vector<std::string> argv;  // the child's command line
  int status = -1;                // its exit status (-1: it did not run or did not exit normally)
  uint64_t mismatch_cycle = 0;    // the file cycle (1-based) of its first mismatching sample, 0 none
  uint64_t file_mismatch_cycle = 0;  // ... of its first output differing from the file's expectation
  std::string first;              // its first mismatch line (the scoreboard's)
  std::string error;              // it could not run, crashed, or printed no result: why, its stderr
  bool fst_written = false;       // the waveform exists and is not empty
  // It failed, first at the file's last cycle, against the file there.
  bool failsAtLastCycle(uint64_t cycles) const {
    return status == 1 && mismatch_cycle == cycles && file_mismatch_cycle == cycles;
  }
  std::string command() const;  // argv, shell-quoted where needed
};

// Runs the child (this executable: /proc/self/exe, else o.argv0) and collects its result.
ScFailReplay replayFailCase(const ScOptions& o, const ScFailCase& c);

}  // namespace shd
