// The stimulus of the checked-in vector files (vectors/cycles/, `shadesim vectors`): seeded,
// a few thousand cycles per configuration, with every expected output from the golden model.
//
// spec: first the corners, valid on every cycle: shininess codes {0, 1, depth/2, last table
//   entry, depth-1 (padding: the all-zero word)} x cos codes {0, 1, 1.0/2, 1.0 - 1 LSB, 1.0,
//   1.0 + 1 LSB, the largest code (saturates to 1.0)} x light {0, full scale, (1, mid, max-1)};
//   degree 3: cos one code below, at and above the cut-off code of every eighth table entry and
//   the last; then RandomSpecStimulus (model/device/spec_stimulus.h: near-1 and above-1 cosines, valid dropped for
//   1..3 cycles with probability 0.2, inputs changing on idle cycles) up to the cycle count.
// span: descriptors from triangle setup of generator triangles (model/raster/trigen.h):
//   1. one triangle of every size class x every shape (5 x 6; zero-area ones are dropped by
//      setup and never reach the unit) in a 16 x 12 viewport, small enough that a large or
//      screen-filling triangle (clipped to it) takes about a hundred cycles, not 10^5;
//   2. with more than one lane-triangle (sierpinski) only: large and screen-sized off-screen
//      triangles and slivers that have a lane group with no valid lane (pre-screened on a
//      scratch model), with out_ready high 30 % of the cycles, until such a group has met
//      out_ready low (the unit must not stall on it), at most 8;
//   3. 24 pixel-to-mesh-sized triangles in a 4096 x 4096 viewport (pixel coordinates using all
//      12 bits of the fragment ports, attributes with other fraction bits);
//   4. the default generator mix in a 40 x 30 viewport until the cycle count is reached.
//   Per triangle the consumer's readiness is drawn from {always, 75 %, 30 %} (out_ready
//   back-pressure), and a descriptor is offered after 1..3 idle cycles of the unit with
//   probability 0.3, else at once (so it also waits, offered, while the unit is busy). The file ends after
//   exactly `cycles` cycles, possibly inside a triangle; its header states ("# coverage: ...")
//   how many descriptors of each phase were accepted, the cycle by which phases 1 to 3 were
//   done, and how often the control corners occurred (stalled outputs, offers waiting, idle
//   gaps, lane groups without a valid lane, counted from the model).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "config/registry.h"
#include "vectors/vector_file.h"

namespace shd {

struct VectorGenSummary {
  uint64_t cycles = 0;
  uint64_t valid_inputs = 0;  // spec: valid vectors; span: descriptors accepted
  uint64_t fragments = 0;     // span: lane fragments handed over (valid lane, out_valid, out_ready)
  uint64_t dropped = 0;       // span: generator triangles setup dropped (zero area, off-screen)
  int phases_done = 0;        // span: of the directed phases 1 to 3, how many the file completes
  std::string text() const;
};

// The configuration's PROM table is built from its JSON; `prom_file` is the file that holds it
// (the caller writes it, or checks a given one with requirePromFileHoldsTable), referred to in
// the header relative to `out_dir` (the directory the vector file goes to).
SpecVectors generateSpecVectors(const SpecUnitConfig& cfg, uint64_t cycles, uint64_t seed, const std::string& prom_file,
                                const std::string& out_dir, VectorGenSummary* summary = nullptr);
// The vector file `output` and the configuration's PROM beside it as `output`.hex (the file the
// header refers to), written together (io/files.h OutputFiles: both or neither).
void writeSpecVectorsWithProm(const SpecUnitConfig& cfg, uint64_t cycles, uint64_t seed, const std::string& output,
                              VectorGenSummary* summary = nullptr);
// The same with the given inputs, one per cycle, then idle cycles until every result has left
// (latency()); `source` is the header's "# source" (how the inputs were made).
void writeSpecInputVectorsWithProm(const SpecUnitConfig& cfg, const std::vector<SpecIn>& inputs,
                                   const std::string& source, const std::string& output);
// `prom_file` must hold exactly the configuration's table: the expected outputs depend on it
// (std::runtime_error naming the first differing address otherwise).
void requirePromFileHoldsTable(const SpecUnitConfig& cfg, const std::string& prom_file);

SpanVectors generateSpanVectors(const SpanUnitConfig& cfg, uint64_t cycles, uint64_t seed,
                                VectorGenSummary* summary = nullptr);

}  // namespace shd
