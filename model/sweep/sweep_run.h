// A sweep's files. A sweep runs into an existing directory DIR:
//   DIR/sweep-plan.json      what is swept (unit, base configuration, axes, PROM request, tool
//                            version, the command); its hash names the sweep
//   DIR/point-<index>.json   one record per evaluated point, each written atomically, so a killed
//                            sweep started again skips the points already recorded
//   DIR/area-<index>.json    the area of a point that may reach a front (areaDominators), written
//                            after every point is recorded, each atomically too
//   DIR/sweep.json, sweep.csv, pareto.csv
//                            the results, written once every point (and area) is recorded (by
//                            the run that records the last one, or by sweep-merge from shard
//                            directories)
// A directory holding another sweep's plan is refused; a point file that does not belong to its
// plan (corrupted, edited, of another sweep) is an error naming it.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
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

// Runs `work(index)` for each of `indices` not in `done` with `jobs` threads, writing each
// result (with the plan's hash) to DIR/<prefix>-<index>.json as it finishes and adding it to
// `done`; `progress(recorded, total)` is called after each. The first exception stops the run
// (results already written stay) and is rethrown.
void runSweepJobs(const std::string& dir, const SweepPlan& plan, const std::string& prefix,
                  const std::vector<uint64_t>& indices, unsigned jobs,
                  const std::function<nlohmann::json(uint64_t)>& work, SweepRecords& done,
                  const std::function<void(uint64_t, uint64_t)>& progress);

// The grid of a plan (its "axes").
Grid planGrid(const SweepPlan& plan);

// The indices of the plan's points in `shard`.
std::vector<uint64_t> shardPoints(const SweepPlan& plan, const Shard& shard);

// The indices of the plan's points missing from `records`.
std::vector<uint64_t> missingPoints(const SweepPlan& plan, const SweepRecords& records);

// Area, the second phase of a sweep whose plan asks for it ("area" other than "none"), run once
// every point's record is there (by the run that records the last point, or by sweep-merge).
// Which points can still reach an error-area front: point p cannot when another point q of the
// grid is no wider than p on every axis, of the same `classes` entry (when given: the DSP
// count each target maps the point's multipliers to, dspClasses() in area.h), and has at most
// p's front error (plan "front" "error"), for then q has at most p's area too IF area does not
// decrease when a width grows while the multipliers map alike (an assumption about the
// synthesis tool, which docs/sweeps.md checks on a grid synthesised at every point; without the
// classes it fails on iCE40, where a narrower product can fall out of a DSP into LUTs) and p
// adds nothing to any front of error against an area figure. Such a q is found for each point
// through its neighbours one value lower on one axis (the least error of everything of its
// class below p, reached through points of its class). Returns, per point, -1 for a point to
// synthesise, else the index of a q (the least-error one, then the least index). With the
// plan's "area_all" every point is synthesised.
std::vector<int64_t> areaDominators(const SweepPlan& plan, const SweepRecords& records,
                                    const std::vector<std::string>& classes = {});

// The area records in DIR (area-<index>.json), checked like the point records.
SweepRecords readSweepAreas(const std::string& dir, const SweepPlan& plan);

// The records of a complete sweep in index order, without "plan", each with its "area" or, where
// the area phase's `dominator` (areaDominators()) ruled it out, "area_pruned_by" (with area;
// std::logic_error when `areas` lacks one it needs or `dominator` is not one per point).
nlohmann::json sweepResults(const SweepPlan& plan, const SweepRecords& records, const SweepRecords& areas = {},
                            const std::vector<int64_t>& dominator = {});

// sweep.json, sweep.csv and pareto.csv of a complete sweep into DIR, as one set of files, from
// its results (sweepResults). The same plan and records give the same bytes.
void writeSweepResults(const std::string& dir, const SweepPlan& plan, const nlohmann::json& results);

// The sum of a record's integer parameters (the member `params`): "the fewest parameter bits"
// that breaks ties between points.
int64_t paramBits(const nlohmann::json& record, const std::string& params);

// Joins shard directories of one sweep: the same plan (else std::runtime_error naming both
// directories and hashes) and together every point (else an error naming the missing points).
// Claims `out` like a sweep directory and writes the plan and every point's record there (so that
// `out` is the finished sweep's directory, like an unsharded run's); returns them. The caller then
// runs the area phase, if any, into `out` and writes the results there.
std::pair<SweepPlan, SweepRecords> mergeSweeps(const std::vector<std::string>& dirs, const std::string& out);

}  // namespace shd
