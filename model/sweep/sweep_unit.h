// What a sweep needs of the unit it sweeps. The one list of the units a sweep can vary is in
// sweep_unit.cpp; each unit is built by its own file here (spec_sweep.h, and the others beside
// it).
//
// A point is the base configuration with the grid's values (sweep/grid.h). Its record, a JSON
// object, is deterministic (the same bytes on every machine and run: no timings, no paths) and
// holds "index", "hash" (of its parameters), the parameters as an object named by
// `params_member`, "error": {figures}, and further top-level numbers (costs such as latency).
// Its area, when the unit has RTL, is computed apart (sweep_run.h): only for the points that can
// still reach a Pareto front.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sweep/area.h"
#include "sweep/grid.h"

namespace shd {

struct SweepUnit {
  std::string name;                 // "spec"
  std::vector<std::string> params;  // the names a --param may vary
  std::string params_member;        // the record's member holding the point's parameters ("rtl")
  nlohmann::json base;              // what the plan records of the base configuration
  std::string base_options;         // the options of `shadesim sweep` that give this base
  // The error figure of the fronts (a member of the record's "error") and the costs it is
  // weighed against (top-level numbers of the record; with --area also <target>_luts).
  std::string front_error;
  std::vector<std::string> front_costs;
  // Every point checked before any work: std::invalid_argument naming the point and the
  // derivation its widths break.
  std::function<void(const Grid&)> validate;
  // The record of point `index` with these values.
  std::function<nlohmann::json(uint64_t index, const PointValues&)> evaluate;
  // The point's area (area.h), or empty when the unit has no RTL to synthesise; then also its
  // RTL parameters (the "rtl" of a configuration file: what dspClasses() reads).
  std::function<nlohmann::json(const PointValues&, const SynthTool&)> area;
  std::function<nlohmann::json(const PointValues&)> rtl;
  // For --target-lsb (empty if the unit has none): the point as a configuration file's JSON
  // (config/registry.h) named `name`, and the internal widths a chosen point is shown minimal
  // in (each one bit narrower must break the target).
  std::function<nlohmann::json(const PointValues&, const std::string& name, const std::string& description)> config;
  std::vector<std::string> widths;
};

// A bundled scene's name: [a-z0-9_]+ (no path).
bool isSceneName(const std::string& name);

// The file of a bundled scene a sweep renders: vectors/scenes/<name>.json of the installation or
// the source tree (findShareFile). std::invalid_argument for a name that is not [a-z0-9_]+ or
// no such file.
std::string sweepSceneFile(const std::string& name);

// The units a sweep can vary ("spec", ...), and one line on each for --help.
std::vector<std::string> sweepUnitNames();
std::string sweepUnitHelp();

// The unit of a sweep's base (the plan's "base": {"unit": name, ...}, made by the unit's
// <unit>SweepBase()). std::invalid_argument for another name or a malformed base.
SweepUnit makeSweepUnit(const nlohmann::json& base);

}  // namespace shd
