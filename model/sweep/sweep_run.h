// A sweep's files. A sweep runs into an existing directory DIR:
//   DIR/sweep-plan.json      what is swept (unit, base configuration, axes, PROM request, tool
//                            version, the command); its hash names the sweep
//   DIR/point-<index>.json   one record per evaluated point, each written atomically, so a killed
//                            sweep started again skips the points already recorded
//   DIR/sweep.json, sweep.csv, pareto.csv
//                            the results, written once every point is recorded (by the run that
//                            records the last one, or by sweep-merge from shard directories)
// A directory holding another sweep's plan is refused; a point file that does not belong to its
// plan (corrupted, edited, of another sweep) is an error naming it.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sweep/grid.h"

namespace shd {

struct SweepPlan {
  nlohmann::json json;  // as in sweep-plan.json, without "hash"
  std::string hash;     // textHash of json.dump()

  static SweepPlan make(nlohmann::json plan);
};

// Records of a sweep's points, by index.
using SweepRecords = std::map<uint64_t, nlohmann::json>;

// Makes DIR the plan's: writes sweep-plan.json, or checks that the one there is this plan.
// std::runtime_error: not a directory, or a directory of another sweep (both hashes named).
void claimSweepDir(const std::string& dir, const SweepPlan& plan);

// The plan in DIR/sweep-plan.json. std::runtime_error naming the file if it is missing or is no
// sweep plan (its hash must match its content).
SweepPlan readSweepPlan(const std::string& dir);

// The point records in DIR, each checked against the plan (its "plan" hash, an index below the
// plan's point count, the index in its name). std::runtime_error naming a file that fails.
SweepRecords readSweepRecords(const std::string& dir, const SweepPlan& plan);

// Evaluates the points of `shard` not in `done` with `jobs` threads, writing each record to
// DIR/point-<index>.json as it finishes and adding it to `done`. `evaluate(index)` returns the
// record; `progress(recorded, total)` is called after each. The first exception of an
// evaluation stops the run (points already written stay) and is rethrown.
void runSweepPoints(const std::string& dir, const SweepPlan& plan, const Shard& shard, unsigned jobs,
                    const std::function<nlohmann::json(uint64_t)>& evaluate, SweepRecords& done,
                    const std::function<void(uint64_t, uint64_t)>& progress);

// The indices of the plan's points missing from `records`.
std::vector<uint64_t> missingPoints(const SweepPlan& plan, const SweepRecords& records);

// sweep.json, sweep.csv and pareto.csv of a complete sweep into DIR, as one set of files. The
// same plan and records give the same bytes.
void writeSweepResults(const std::string& dir, const SweepPlan& plan, const SweepRecords& records);

// Joins shard directories of one sweep: the same plan (else std::runtime_error naming both
// directories and hashes) and together every point (else an error naming the missing points).
// Writes the plan and the results into `out` (claimed like a sweep directory).
void mergeSweeps(const std::vector<std::string>& dirs, const std::string& out);

}  // namespace shd
