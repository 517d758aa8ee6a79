// One point of a specular-unit sweep, evaluated by the model: the base configuration's
// parameters with the grid's values, its PROM built by the sweep's fit, and its error
// (report/spec_error.h: at full light; a lower light only scales the error down, the final
// rounding aside) found exhaustively, every cosine code 0..2^CosFracBits at every shininess of
// the PROM, when those are at most kSpecExhaustiveInputs, else on a seeded sample of codes plus
// the corners (specSampleCodes); its latency and its PROM size.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "device/prom.h"
#include "device/spec_params.h"
#include "sweep/area.h"
#include "sweep/sweep_unit.h"

namespace shd {

// The base parameters with `values` set (names as in SpecUnitParams::toJson). std::invalid_argument
// naming the point and the derivation a width breaks (SpecUnitParams::validate).
SpecUnitParams specPointParams(const SpecUnitParams& base, const PointValues& values);

constexpr uint64_t kSpecExhaustiveInputs = uint64_t{1} << 28;
constexpr uint64_t kSpecSampleSeed = 20261125;

// The cosine codes a point evaluates: empty (all of them) when (2^CosFracBits + 1) * entries is
// at most kSpecExhaustiveInputs; otherwise, ascending, 0, 1, 2, the middle, the three highest
// codes and codes drawn by SplitMix64 from `seed`, kSpecExhaustiveInputs / entries (at least 64)
// in all. The same on every machine.
std::vector<int64_t> specSampleCodes(const SpecUnitParams& p, size_t entries, uint64_t seed);

// The parameter names a specular sweep may vary.
std::vector<std::string> specParamNames();

// The point's record: {"index", "hash", "rtl", "error": {...}, "latency", "prom_bits", "rom_bits"
// (the PROM and the fixed tables of the explog kind: SpecUnitParams::fixedRomBits),
// "inputs", "exhaustive" (1 or 0: sampled)}. Deterministic: the same parameters and request
// give the same record, byte for byte, on any machine (no timings in it).
nlohmann::json evaluateSpecPoint(uint64_t index, const SpecUnitParams& p, const PromRequest& req);

// The base of a specular sweep as its plan records it: {"unit": "spec", "config": what --config
// names, "rtl": the parameters, "prom": the configuration's "prom" member}.
nlohmann::json specSweepBase(const std::string& config, const SpecUnitParams& rtl, const PromContent& prom);

// The specular unit as a sweep sees it: the base's parameters with the grid's values, each
// point's PROM built by the base's request. validate() builds the PROM of every distinct
// coefficient format (coefficients that do not fit stop the sweep); the fronts weigh
// datapath_max_lsb against latency and ROM bits.
SweepUnit specSweepUnit(const nlohmann::json& base);

// The hash naming a point's parameters (textHash of its "rtl" object).
std::string specPointHash(const SpecUnitParams& p);

}  // namespace shd
