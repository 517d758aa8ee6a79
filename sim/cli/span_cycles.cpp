// shadesim span-cycles: the span unit's cycles per configuration (lane mode, paper's or full-rate
// unit) on the generator's size classes and on scenes (builtin:sphere and builtin:torus unless
// --scene names others), the paper's speed-up claims, optionally checked against the RTL
// (report/span_cycles.h).
#include <algorithm>
#include <cstdio>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli/command.h"
#include "cli/options.h"
#include "cosim/span_cosim.h"
#include "device/prom_io.h"
#include "raster/desc_stream.h"
#include "raster/trigen.h"
#include "report/span_cycles.h"
#include "scene/scene.h"
#include "scene/sphere.h"
#include "io/files.h"

namespace shd::cli {

namespace {

using NamedList = std::pair<std::string, TriangleList>;

class SpanCyclesCmd final : public Command {
 public:
  void add(CLI::App& app) override {
    app.add_option("--triangles", triangles_,
                   "triangles per size class and for the mixed stream; large: 1/20 of it, screen-filling: 1/2000 "
                   "(at least 5), so that every set costs about the same; the sets are held in memory")
        ->check(countIn(1, kMaxTriangles));
    app.add_option("--seed", seed_, "generator seed")->check(countIn(0, UINT64_MAX));
    app.add_option("--divider-latency", divider_latency_, "divider latencies (cycles) of the classical unit")
        ->delimiter(',')
        ->check(countIn(0, 1000));
    app.add_option("--soft-repeats", soft_repeats_, "repeats of the software timing (median)")
        ->check(countIn(1, 1000));
    app.add_flag("--json", json_, "print one JSON object instead of the tables");
    app.add_option("--json-out", json_out_, "also write the JSON object to this file");
    app.add_option("--scene", scenes_, "scenes whose front faces are sets too: builtin:<name>, a scene file or a mesh file")
        ->delimiter(',');
    app.add_flag("--rtl", rtl_, "also run every set through the verilated unit of every mode and check its cycles");
  }

  int run(const CLI::App&) override {
    if (!json_out_.empty()) outputTarget(json_out_);  // refused before the work, not after it
    const std::vector<SpanUnitConfig> modes = spanCyclesConfigs();
    if (rtl_)
      for (const SpanUnitConfig& m : modes) requireVerilated(m);
    const std::vector<NamedList> lists = triangleSets();
    std::vector<TriangleSetCycles> sets;
    for (const auto& [name, list] : lists) {
      std::fprintf(stderr, "span-cycles: %s (%zu triangles)\n", name.c_str(), list.size());
      sets.push_back(measureSpanCycles(name, list, RasterConfig{}, modes, divider_latency_, soft_repeats_));
    }
    nlohmann::json j = {{"seed", seed_}, {"triangles_per_class", triangles_}, {"sets", nlohmann::json::array()}};
    for (const auto& s : sets) j["sets"].push_back(toJson(s));
    std::string rtl_lines;
    const bool rtl_ok = !rtl_ || checkRtl(lists, modes, sets, j, rtl_lines);
    if (!json_out_.empty()) writeFileAtomic(json_out_, j.dump(2) + "\n");
    if (json_) std::cout << j.dump(2) << "\n";
    else
      std::cout << renderSpanCyclesTable(sets)
                << (rtl_ ? "\nChecked against the RTL (verilated, cycle by cycle):\n" + rtl_lines : "");
    return rtl_ok ? 0 : 1;
  }

 private:
  // The sets are held in memory: at the limit about 1 GB (4 sets of this many triangles).
  static constexpr uint64_t kMaxTriangles = 1'000'000;
  uint64_t triangles_ = 20000, seed_ = 1;
  std::vector<int> divider_latency_{1, 4, 8, 16, 32};
  int soft_repeats_ = 5;
  bool json_ = false, rtl_ = false;
  std::string json_out_;
  std::vector<std::string> scenes_{"builtin:sphere", "builtin:torus"};

  // The generator's size classes, the mixed stream and the scenes (--scene).
  std::vector<NamedList> triangleSets() const;
  // The cycle counts checked against the RTL: the same triangles through the verilated unit of
  // each mode, consumer always ready, compared cycle by cycle with the model.
  static bool checkRtl(const std::vector<NamedList>& lists, const std::vector<SpanUnitConfig>& modes,
                       const std::vector<TriangleSetCycles>& sets, nlohmann::json& j, std::string& lines);
};

std::vector<NamedList> SpanCyclesCmd::triangleSets() const {
  std::vector<NamedList> lists;
  const RasterConfig rc;
  auto classStream = [&](const char* name, int cls) {
    uint64_t count = triangles_;
    if (cls == static_cast<int>(SizeClass::Large)) count = std::max<uint64_t>(5, triangles_ / 20);
    if (cls == static_cast<int>(SizeClass::Screen)) count = std::max<uint64_t>(5, triangles_ / 2000);
    TriGenOptions g;
    if (cls >= 0) {
      g.size_weight = {0, 0, 0, 0, 0};
      g.size_weight[static_cast<size_t>(cls)] = 1;
    }
    TriangleGenerator gen(seed_, g);
    TriangleList list;
    for (uint64_t i = 0; i < count; ++i) list.push_back(toSetupVertices(gen.next(), rc.unit.NumAttr));
    lists.emplace_back(name, std::move(list));
  };
  const char* names[] = {"pixel1", "small", "mesh 10-100px", "large", "screen"};
  for (int cls = 0; cls < kNumSizeClasses; ++cls) classStream(names[cls], cls);
  classStream("mixed", -1);
  // Each scene's front faces (every object, in scene order) as its camera sees them;
  // attributes: the normal mapped to colour, and depth.
  for (const std::string& spec : scenes_) {
    const Scene scene = loadScene(spec);
    TriangleList tris;
    for (const SceneObject& obj : scene.objects)
      for (const ScreenTriangle& t : projectFrontFaces(worldMesh(obj), scene.camera)) {
        std::array<SetupVertex, 3> v;
        for (size_t i = 0; i < 3; ++i)
          v[i] = {t.v[i].x,
                  t.v[i].y,
                  {127.5 * (t.v[i].n.x + 1), 127.5 * (t.v[i].n.y + 1), 127.5 * (t.v[i].n.z + 1), t.v[i].z / 4}};
        tris.push_back(v);
      }
    lists.emplace_back(spec, std::move(tris));
  }
  return lists;
}

bool SpanCyclesCmd::checkRtl(const std::vector<NamedList>& lists, const std::vector<SpanUnitConfig>& modes,
                             const std::vector<TriangleSetCycles>& sets, nlohmann::json& j, std::string& lines) {
  bool all_ok = true;
  for (size_t si = 0; si < lists.size(); ++si)
    for (size_t mi = 0; mi < modes.size(); ++mi) {
      RasterConfig c;
      c.unit = modes[mi].rtl;
      size_t next_tri = 0;
      const TriangleList& list = lists[si].second;
      SpanCosimOptions o;
      o.ready_prob = 1.0;
      o.desc_gap_prob = 0.0;
      o.drain_every = 0;  // back to back, as measured
      const SpanCosimResult r = runSpanCosim(
          modes[mi].name,
          [&](SpanDesc& d) {
            while (next_tri < list.size()) {
              SetupResult s = setupTriangle(list[next_tri], static_cast<uint32_t>(next_tri), c);
              ++next_tri;
              if (s.desc) {
                d = std::move(*s.desc);
                return true;
              }
            }
            return false;
          },
          o);
      const uint64_t model_cycles = sets[si].modes[mi].cycles;
      const bool ok = r.mismatches == 0 && r.cycles == model_cycles;
      all_ok = all_ok && ok;
      j["sets"][si]["modes"][mi]["rtl_cycles"] = r.cycles;
      j["sets"][si]["modes"][mi]["rtl_mismatches"] = r.mismatches;
      lines += fmt::format("{:<16} {:<11} model {:>10} rtl {:>10} cycles, {} mismatches{}\n", lists[si].first,
                           modes[mi].name, model_cycles, r.cycles, r.mismatches, ok ? "" : "  <-- FAIL");
    }
  return all_ok;
}

}  // namespace

std::unique_ptr<Command> makeSpanCyclesCmd() { return std::make_unique<SpanCyclesCmd>(); }

}  // namespace shd::cli
