// Cycles of the span unit per configuration on a set of triangles (from the cycle-accurate
// model and, for the full-rate unit, the walker's stream timing), and the paper's comparisons:
//   - speed-up of each lane mode over the serial unit (the paper: 2x for even/odd, 4x for the
//     4-way Sierpinski split) and the lane utilisation (fragments per lane-cycle in SPAN);
//   - constant increment vs the classical per-line division (the paper: 1.7x): the classical
//     unit is the serial unit plus a divider of latency D on every raster line whose span has
//     two or more pixels (a one-pixel span needs no step), so its cycles are
//     serial cycles + D * divisions, for each D asked; and the same comparison as software time
//     (raster/soft_raster.h), median of repeated runs.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "config/registry.h"
#include "raster/setup.h"

namespace shd {

struct ModeCycles {
  std::string mode;  // the span configuration's name
  bool row_ahead = false;  // the full-rate unit (SpanParams::RowAhead)
  uint64_t triangles = 0;  // drawn (setup kept them)
  uint64_t fragments = 0;
  // The triangles back to back, each from the cycle the unit can take it, the consumer always
  // ready: the paper's unit runs one at a time (its cycles are the sum of each alone); the
  // full-rate unit overlaps them (the walker's SpanStream).
  uint64_t cycles = 0;
  // Walker rows (the paper's ROW cycles) and lane groups (SPAN cycles). span_cycles is also the
  // no-overhead bound of the lane layout: its lane groups alone, as if every row and triangle
  // transition were free.
  uint64_t row_cycles = 0, span_cycles = 0;
  int lanes = 1;
  double utilisation() const {
    return span_cycles ? static_cast<double>(fragments) / (static_cast<double>(span_cycles) * lanes) : 0.0;
  }
  double overBound() const { return span_cycles ? static_cast<double>(cycles) / static_cast<double>(span_cycles) : 0.0; }
  double fragmentsPerCycle() const { return cycles ? static_cast<double>(fragments) / static_cast<double>(cycles) : 0.0; }
};

struct TriangleSetCycles {
  std::string name;
  uint64_t input_triangles = 0;
  std::vector<ModeCycles> modes;  // the order of the configurations measured: serial first
  uint64_t divisions = 0;         // serial raster lines with >= 2 pixels
  std::vector<int> divider_latency;
  double soft_ms_classical = 0, soft_ms_constant = 0;  // median over repeats
  uint64_t soft_divisions = 0;
};

using TriangleList = std::vector<std::array<SetupVertex, 3>>;

// The span configurations of the registry, the paper's serial unit (one lane, RowAhead 0) first
// and the others in registry order, each full-rate unit right after the paper's unit of the same
// parameters. std::invalid_argument when the registry has no paper's serial unit.
std::vector<SpanUnitConfig> spanCyclesConfigs();

// modes: the configurations to measure, the serial unit (one lane) first: the speed-ups and
// the classical unit's cycles are relative to it.
TriangleSetCycles measureSpanCycles(const std::string& name, const TriangleList& tris, const RasterConfig& base,
                                    const std::vector<SpanUnitConfig>& modes, const std::vector<int>& divider_latency,
                                    int soft_repeats);

nlohmann::json toJson(const TriangleSetCycles& s);
std::string renderSpanCyclesTable(const std::vector<TriangleSetCycles>& sets);

}  // namespace shd
