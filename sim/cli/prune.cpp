// shadesim prune: what one scene needs of the units, as it is rendered (docs/prune.md).
// Renders the scene with the full configurations through recording specular engines; writes the
// analysis, a PROM per device lobe holding only the shininess values the scene uses (every
// format, the address map and the material-to-address table), the lane mode with the fewest
// cycles on this scene (each measured), what the scene leaves unused and why, and the proof: the
// scene rendered with the pruned PROMs in the chosen mode against the full configuration
// (at most E LSB apart) and each pruned specular configuration replayed under Icarus.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli/command.h"
#include "cli/hardware.h"
#include "cli/options.h"
#include "cli/render_common.h"
#include "cli/sweep_target.h"
#include "cosim/render_rtl.h"
#include "harness/span_dut.h"
#include "device/prom.h"
#include "device/prom_io.h"
#include "io/files.h"
#include "render/lobe_units.h"
#include "render/methods.h"
#include "report/scene_use.h"
#include "scene/scene.h"
#include "sweep/spec_sweep.h"
#include "vectors/vector_gen.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace shd::cli {

namespace {

constexpr uint64_t kPruneVerifyCycles = 20000;  // the Icarus replay of each pruned configuration

// The units --drop can leave out, and the device lobes each one evaluates (none: the span unit).
struct DropPart {
  const char* name;
  std::vector<Lobe> lobes;
};
const std::vector<DropPart>& dropParts() {
  static const std::vector<DropPart> parts = {{"span", {}},
                                              {"spec", {Lobe::Quadratic, Lobe::Cubic}},
                                              {"spec-quadratic", {Lobe::Quadratic}},
                                              {"spec-cubic", {Lobe::Cubic}}};
  return parts;
}

// One device lobe of the scene: its full configuration, what the scene asked of it, its pruned
// PROM.
struct LobePrune {
  Lobe lobe = Lobe::Quadratic;
  SpecUnitConfig full, pruned;
  std::unique_ptr<ModelSpecEngine> full_engine, pruned_engine;
  std::unique_ptr<RecordingSpecEngine> recorder, pruned_recorder;  // the full frame's, the pruned frame's
  std::vector<double> n_used;  // the shininess values requested, ascending
  std::vector<uint32_t> cos_min;  // per n_used entry the least cosine code requested
  json narrowed = json::array();  // {"width", "from", "to"} per width narrowed
  json one_less = json::object();  // per width: what one bit fewer breaks
};

// The largest difference of two frames' channel values (LSB), and how many differ.
std::pair<int, uint64_t> frameDifference(const RenderResult& a, const RenderResult& b) {
  int max_diff = 0;
  uint64_t differ = 0;
  for (size_t i = 0; i < a.fb.rgb.size(); ++i) {
    const int d = std::abs(int(a.fb.rgb[i]) - int(b.fb.rgb[i]));
    max_diff = std::max(max_diff, d);
    differ += d > 0;
  }
  return {max_diff, differ};
}

class PruneCmd final : public Command {
 public:
  void add(CLI::App& app) override;
  int run(const CLI::App& app) override;

 private:
  std::string scene_ = "builtin:sphere", dir_, method_ = "phong-fixed", brdf_;
  std::vector<std::string> drop_;
  HardwareOptions hardware_;
  LobeConfigs lobes_;
  double target_lsb_ = 0;
  bool quiet_ = false;

  void say(const std::string& m) const {
    if (!quiet_) std::fprintf(stderr, "prune: %s\n", m.c_str());
  }
  void checkScene(const Scene& sc) const;
  json checkDropped(const Scene& sc, const RenderOptions& ro) const;
  json laneModes(const Scene& sc, const RenderOptions& ro, const SpecEngines& full, const RenderResult& ref,
                 std::string& best) const;
  void prunePromOf(LobePrune& lp) const;
  void narrowWidths(const Scene& sc, const RenderOptions& ro, const SpanParams& mode, const RenderResult& full,
                    std::vector<LobePrune>& lobes) const;
  void writePruned(const LobePrune& lp, OutputFiles& out, json& lobe_json) const;
  json hardwareFigures(const std::vector<LobePrune>& lobes, Hardware& hw) const;
  json rtlProof(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& mode, const RenderResult& pruned,
                const SpecEngines& pruned_engines, const std::vector<LobePrune>& lobes, bool& ok) const;
  json unusedParts(const RenderOptions& ro, const SpanParams& mode, const std::vector<LobePrune>& lobes) const;
};

void PruneCmd::add(CLI::App& app) {
  app.add_option("--scene", scene_, "builtin:sphere | builtin:plane | builtin:torus | builtin:materials, a scene JSON "
                                    "file or a mesh file")
      ->default_val(scene_);
  std::vector<std::string> methods;
  for (const Method m : allMethods()) methods.emplace_back(toString(m));
  app.add_option("--method", method_, "the shading method the scene is rendered with: " + fmt::format("{}", fmt::join(methods, " | ")))
      ->check(CLI::IsMember(methods))
      ->default_val(method_);
  app.add_option("--brdf", brdf_, "override every material's brdf (as for render)")
      ->check(CLI::IsMember({"phong", "blinn", "normalized-blinn", "schlick", "quadratic", "cubic", "cook-torrance",
                             "pow"}));
  app.add_option("--quadratic-config", lobes_.quadratic,
                 "the full specular unit of the quadratic lobe: " + configChoices("spec"))
      ->default_val(lobes_.quadratic);
  app.add_option("--cubic-config", lobes_.cubic, "the full specular unit of the cubic lobe: " + configChoices("spec"))
      ->default_val(lobes_.cubic);
  app.add_option("--target-lsb", target_lsb_,
                 "E: the pruned configuration's image may differ from the full one's by at most E LSB at any pixel")
      ->required()
      ->check(realIn(0, 255));
  app.add_option("-o,--output", dir_, "the directory written (made if missing; its parent must exist)")->required();
  std::vector<std::string> parts;
  for (const DropPart& d : dropParts()) parts.emplace_back(d.name);
  app.add_option("--drop", drop_,
                 fmt::format("units to leave out ({}), comma-separated: refused when the scene, rendered with --method "
                             "and --brdf, needs one",
                             fmt::join(parts, " | ")))
      ->delimiter(',')
      ->check(CLI::IsMember(parts));
  hardware_.add(app, "no area and no place and route of the full and pruned units");
  app.add_flag("--quiet", quiet_, "no progress on stderr");
}

void PruneCmd::checkScene(const Scene& sc) const {
  if (sc.objects.empty()) throw ArgError(fmt::format("--scene {}: no objects: nothing to render, nothing to prune", sc.name));
  if (sc.lights.empty())
    throw ArgError(fmt::format("--scene {}: no lights: every pixel is the ambient term; prune a scene that is lit", sc.name));
  existingOrNewDir("-o", dir_, dir_, "");
  hardware_.check();
}

// The units --drop names, each checked unneeded by the scene as rendered with `ro` (ArgError
// naming what needs it): [{"part", "why"}], why: the reason the scene does without it.
json PruneCmd::checkDropped(const Scene& sc, const RenderOptions& ro) const {
  json dropped = json::array();
  const std::vector<Lobe> used = deviceLobesUsed(sc, ro);
  for (const std::string& name : drop_) {
    refuseRepeat("--drop", drop_, name);
    const auto part = std::find_if(dropParts().begin(), dropParts().end(), [&](const DropPart& d) { return name == d.name; });
    if (part->lobes.empty()) {  // the span unit
      if (!traits(ro.method).exact)
        throw ArgError(fmt::format("--drop span: {} draws every triangle with the span unit; only reference shades without it",
                                   method_));
      dropped.push_back({{"part", name}, {"why", fmt::format("{} shades every pixel directly", method_)}});
      continue;
    }
    for (const Lobe l : part->lobes) {
      if (std::find(used.begin(), used.end(), l) == used.end()) continue;
      std::vector<std::string> objects;
      for (const SceneObject& o : sc.objects) {
        const Material& m = sc.materials.at(static_cast<size_t>(o.material));
        if (parseLobe(brdf_.empty() ? m.brdf : brdf_) == l) objects.push_back(fmt::format("'{}' (material '{}')", o.name, m.name));
      }
      throw ArgError(fmt::format("--drop {}: {} with {} evaluates the {} lobe of {} on the specular unit; leave the unit in, "
                                 "or give --brdf a lobe without it (blinn, phong, pow, ...)",
                                 name, sc.name, method_, toString(l), fmt::join(objects, ", ")));
    }
    std::vector<std::string> lobes;
    for (const Lobe l : part->lobes) lobes.emplace_back(toString(l));
    dropped.push_back({{"part", name},
                       {"why", traits(ro.method).exact ? fmt::format("{} evaluates the lobes exactly", method_)
                                                       : fmt::format("no object's lobe is {}", fmt::join(lobes, " or "))}});
  }
  return dropped;
}

// Every lane mode of the registry on the scene, with the full specular units: cycles per frame,
// each image checked equal to the serial one. `best`: the mode with the fewest cycles.
json PruneCmd::laneModes(const Scene& sc, const RenderOptions& ro, const SpecEngines& full, const RenderResult& ref,
                         std::string& best) const {
  json modes = json::array();
  uint64_t least = UINT64_MAX;
  for (const std::string& name : builtinConfigNames("span")) {
    ModelSpanEngine span(spanConfig(name).rtl);
    const RenderResult r = render(sc, ro, span, full);
    if (r.fb.rgb != ref.fb.rgb)
      throw std::runtime_error(fmt::format("lane mode {} renders another image than serial", name));
    modes.push_back({{"mode", name},
                     {"lanes", spanConfig(name).rtl.lanes()},
                     {"span_cycles", r.stats.span_cycles},
                     {"fragments", r.stats.fragments},
                     {"fragments_per_cycle", r.stats.span_cycles ? static_cast<double>(r.stats.fragments) / r.stats.span_cycles : 0.0}});
    if (r.stats.span_cycles < least) least = r.stats.span_cycles, best = name;
    say(fmt::format("lane mode {}: {} cycles", name, r.stats.span_cycles));
  }
  return modes;
}

// The lobe's configuration with only the shininess values the scene requested in its PROM, in
// ascending order, at the least ShinBits that addresses them.
void PruneCmd::prunePromOf(LobePrune& lp) const {
  std::vector<std::string> n_text;
  for (double n : lp.n_used) n_text.push_back(fmt::format("{}", n));
  lp.pruned = lp.full;
  lp.pruned.name = lp.full.name + "pruned";  // a configuration name is letters and digits
  lp.pruned.description = fmt::format("{} with only the shininess values {} uses (shadesim prune)", lp.full.name, scene_);
  lp.pruned.prom.n = fmt::format("{}", fmt::join(n_text, ","));
  lp.pruned.prom.is_list = true;
  lp.pruned.rtl.ShinBits = addressBitsFor(lp.n_used.size());
  lp.pruned.rtl.validate();
  lp.pruned.cos_code_min = lp.cos_min;  // the pruned model refuses less than the scene reached
  lp.pruned_engine = modelSpecEngine(lp.pruned);
}

// Each internal width of each lobe's unit (the sweep's list for its kind) one bit narrower at a
// time while the scene's image, rendered in the chosen mode, stays within E of the full
// configuration's; until no width can lose a bit. Records what one bit fewer breaks per width.
void PruneCmd::narrowWidths(const Scene& sc, const RenderOptions& ro, const SpanParams& mode, const RenderResult& full,
                            std::vector<LobePrune>& lobes) const {
  ModelSpanEngine span(mode);
  auto view = [&] {
    SpecEngines v;
    for (LobePrune& lp : lobes) v.set(lp.lobe, lp.pruned_engine.get());
    return v;
  };
  for (LobePrune& lp : lobes) {
    const std::vector<std::string> widths = specSweepUnit(specSweepBase(lp.pruned.name, lp.pruned.rtl, lp.pruned.prom)).widths;
    for (bool stepped = true; stepped;) {
      stepped = false;
      for (const std::string& w : widths) {
        SpecUnitConfig c = lp.pruned;
        json rtl = c.rtl.toJson();
        rtl[w] = rtl[w].get<int>() - 1;
        std::unique_ptr<ModelSpecEngine> e;
        try {
          c.rtl = SpecUnitParams::fromJson(rtl, c.name);
          c.rtl.validate();
          e = modelSpecEngine(c);
        } catch (const std::invalid_argument& ex) {
          lp.one_less[w] = {{"breaks", ex.what()}};
          continue;
        }
        std::swap(lp.pruned_engine, e);
        const auto [max_diff, differ] = frameDifference(full, render(sc, ro, span, view()));
        if (max_diff > target_lsb_) {
          std::swap(lp.pruned_engine, e);  // back
          lp.one_less[w] = {{"breaks", fmt::format("the image is {} LSB from the full one's ({} values differ)", max_diff, differ)}};
          continue;
        }
        lp.pruned = c;
        stepped = true;
      }
    }
    for (const std::string& w : widths) {
      const int from = lp.full.rtl.toJson()[w].get<int>(), to = lp.pruned.rtl.toJson()[w].get<int>();
      if (from != to) lp.narrowed.push_back({{"width", w}, {"from", from}, {"to", to}});
    }
    std::vector<std::string> steps;
    for (const json& n : lp.narrowed)
      steps.push_back(fmt::format("{} {} -> {}", n["width"].get<std::string>(), n["from"].get<int>(), n["to"].get<int>()));
    say(fmt::format("{}: {}", lp.pruned.name, steps.empty() ? "no width can lose a bit" : fmt::format("{}", fmt::join(steps, ", "))));
  }
}

// The pruned configuration and its PROM in every format into `out`, its figures into `lobe_json`.
void PruneCmd::writePruned(const LobePrune& lp, OutputFiles& out, json& lobe_json) const {
  const PromTable& t = lp.pruned_engine->table();
  const std::string stem = "spec_" + lp.pruned.name;
  const json cfg = {{"name", lp.pruned.name},
                    {"description", lp.pruned.description},
                    {"rtl", lp.pruned.rtl.toJson()},
                    {"prom", {{"fit", lp.pruned.prom.fit}, {"level", lp.pruned.prom.level}, {"n_list", lp.pruned.prom.n}}},
                    {"inputs", {{"cos_code_min", lp.pruned.cos_code_min}}}};
  out.add(lp.pruned.path, cfg.dump(2) + "\n");
  for (PromFormat f : {PromFormat::Hex, PromFormat::Mem, PromFormat::Coe, PromFormat::Mif, PromFormat::Csv})
    for (const auto& [suffix, text] : renderPromFiles(t, f))
      out.add((fs::path(dir_) / "prom" / (stem + "." + toString(f) + suffix)).string(), text);
  json map = json::array();
  for (const PromEntry& e : t.entries) map.push_back({{"address", e.address}, {"n", e.n}});
  lobe_json["pruned"] = {{"config", stem + ".json"},
                         {"rtl", lp.pruned.rtl.toJson()},
                         {"ShinBits", lp.pruned.rtl.ShinBits},
                         {"prom_bits", lp.pruned.rtl.promBits()},
                         {"narrowed", lp.narrowed},
                         {"one_bit_narrower", lp.one_less},
                         {"address_map", map}};
  lobe_json["full"] = {{"config", lp.full.ref()},
                       {"rtl", lp.full.rtl.toJson()},
                       {"ShinBits", lp.full.rtl.ShinBits},
                       {"prom_bits", lp.full.rtl.promBits()},
                       {"n", lp.full.prom.n}};
}

// The pruned frame on the RTL, with nothing to build. The span unit of the chosen lane mode (a
// registry configuration, verilated into this program) renders the frame with the pruned
// specular models: image and cycles must equal the model's. Each pruned specular unit, whose
// parameters no verilated model has, is simulated by Icarus with the configuration's parameters:
// a vector file of every distinct request of the frame (<config>.frame.vec: the unit's outputs
// are all the frame takes from it), then one of seeded random vectors with gaps (<config>.vec).
json PruneCmd::rtlProof(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& mode, const RenderResult& pruned,
                        const SpecEngines& pruned_engines, const std::vector<LobePrune>& lobes, bool& ok) const {
  json rtl = {{"span", json()}, {"spec", json::array()}};
  auto fail = [&](const std::string& what, const std::string& why) {
    std::fprintf(stderr, "prune: RTL check of %s failed: %s\n", what.c_str(), why.c_str());
    ok = false;
    return why;
  };
  if (!mode.name.empty()) {
    try {
      requireVerilated(mode);
      RtlSpanEngine span(mode, dir_);
      const RenderResult r = render(sc, ro, span, pruned_engines);
      const bool same = r.fb.rgb == pruned.fb.rgb && r.stats.span_cycles == pruned.stats.span_cycles;
      rtl["span"] = {{"config", mode.name}, {"image_equal", r.fb.rgb == pruned.fb.rgb},
                     {"span_cycles", r.stats.span_cycles}, {"cycles_equal", r.stats.span_cycles == pruned.stats.span_cycles}};
      if (!same) fail("span:" + mode.name, "the frame with the verilated span unit differs from the model's");
      say(fmt::format("span:{} in the loop: {} cycles, image {}", mode.name, r.stats.span_cycles, same ? "equal" : "DIFFERENT"));
    } catch (const std::exception& e) {
      rtl["span"] = {{"config", mode.name}, {"error", fail("span:" + mode.name, e.what())}};
    }
  }
  for (const LobePrune& lp : lobes) {
    std::vector<SpecIn> inputs;
    for (const SpecRequest& r : lp.pruned_recorder->distinctRequests()) inputs.push_back(SpecIn{true, r.shin, r.cos, r.light});
    const std::string vec = fs::path(lp.pruned.path).replace_extension(".frame.vec").string();
    json entry = {{"config", lp.pruned.name}, {"frame_requests", inputs.size()}};
    try {
      writeSpecInputVectorsWithProm(lp.pruned, inputs, fmt::format("shadesim prune: the distinct requests of {}", sc.name), vec);
      replayUnderIcarus(vec);
      say(fmt::format("Icarus replayed {} ({} distinct requests of the frame): every output matches the model", vec, inputs.size()));
      say(verifyUnderIcarus(lp.pruned.path, kPruneVerifyCycles));
      entry["icarus"] = "equal";
    } catch (const std::runtime_error& e) {
      entry["icarus"] = fail(lp.pruned.name, e.what());
    }
    rtl["spec"].push_back(entry);
  }
  return rtl;
}

// The area (yosys, iCE40 and xc7) and the place and route (nextpnr) of each lobe's full and
// pruned configuration, computed in parallel, kept in the cache: {"spec": {<config>: {"area",
// "pnr"}}, "absent": [...]}.
json PruneCmd::hardwareFigures(const std::vector<LobePrune>& lobes, Hardware& hw) const {
  json units = {{"spec", json::object()}};
  std::vector<HardwareJob> jobs;
  for (const LobePrune& lp : lobes)
    for (const auto& [name, engine] : {std::pair{lp.full.name, lp.full_engine.get()}, std::pair{lp.pruned.name, lp.pruned_engine.get()}}) {
      const PromTable* t = &engine->table();
      units["spec"][name] = json::object();
      if (hw.pnr)
        jobs.push_back({"spec", name, "pnr", "place and route of " + name, [t, tool = *hw.pnr] { return specPointPnr(*t, tool); }});
      if (hw.synth)
        jobs.push_back({"spec", name, "area", "area of " + name, [t, tool = *hw.synth] { return specPointArea(*t, tool); }});
    }
  runHardwareJobs(jobs, units, hw, [this](const std::string& m) { say(m); });
  units["absent"] = hw.absent;
  return units;
}

// What the scene leaves unused, with the reason for each.
json PruneCmd::unusedParts(const RenderOptions& ro, const SpanParams& mode, const std::vector<LobePrune>& lobes) const {
  json unused = json::array();
  const MethodTraits& tr = traits(ro.method);
  if (tr.exact)
    unused.push_back({{"part", "span unit"}, {"why", fmt::format("{} shades every pixel directly, without the span unit", method_)}});
  if (lobes.empty())
    unused.push_back({{"part", "specular unit"},
                      {"why", tr.exact ? fmt::format("{} evaluates the lobes exactly, without the unit", method_)
                                       : "no visible object has a device lobe (quadratic or cubic): the unit gets no request"}});
  for (const LobePrune& lp : lobes) {
    bool lit = false;
    for (const auto& item : lp.recorder->use()) lit = lit || item.second.light_max > 0;
    if (!lit)
      unused.push_back({{"part", fmt::format("specular unit of the {} lobe", toString(lp.lobe))},
                        {"why", "every request carries light code 0 (k_s = 0 or no light reaches it): its output is never seen"}});
  }
  if (ro.method == Method::Flat)
    unused.push_back({{"part", "span attribute lanes 0..2 (the colour) as interpolators"},
                      {"why", "flat shades once per polygon: the colour's increments are 0, a register per triangle holds it"}});
  // The span unit's attributes 0..2 carry the colour or the normal, 3 the depth (render.h).
  const int attrs = mode.NumAttr;
  if (attrs > 4)
    unused.push_back({{"part", fmt::format("span attribute lanes 4..{}", attrs - 1)},
                      {"why", "the renderer interpolates 4 attributes: 3 of colour or normal and the depth"}});
  return unused;
}

int PruneCmd::run(const CLI::App&) {
  const Scene sc = loadScene(scene_);
  checkScene(sc);
  RenderOptions ro;
  ro.method = parseMethod(method_);
  ro.brdf = brdf_;
  const json dropped = checkDropped(sc, ro);
  // 1. The full configurations, as rendered: every specular request recorded.
  std::vector<LobePrune> lobes;
  SpecEngines full_view, rec_view;
  for (Lobe l : deviceLobesUsed(sc, ro)) {
    LobePrune lp;
    lp.lobe = l;
    lp.full = lobeConfigArg(lobes_, l);
    lp.full_engine = modelSpecEngine(lp.full);
    lp.recorder = std::make_unique<RecordingSpecEngine>(*lp.full_engine);
    full_view.set(l, lp.full_engine.get());
    rec_view.set(l, lp.recorder.get());
    lobes.push_back(std::move(lp));
  }
  say(fmt::format("{} with {}: {} device lobe(s)", sc.name, method_, lobes.size()));
  ModelSpanEngine serial(spanConfig("serial").rtl);
  const RenderResult full = render(sc, ro, serial, rec_view);
  // 2. The lane mode with the fewest cycles (none for the exact method: no span unit).
  std::string best = "serial";
  const bool uses_span = !traits(ro.method).exact;
  const json modes = uses_span ? laneModes(sc, ro, full_view, full, best) : json::array();
  // 3. Per lobe the PROM of the shininess values used (ascending, each with the least cosine
  // requested), then its widths narrowed within E.
  for (LobePrune& lp : lobes) {
    std::vector<std::pair<double, uint32_t>> used;
    for (const PromEntry& e : lp.full_engine->table().entries) {
      const auto u = lp.recorder->use().find(e.address);
      if (u != lp.recorder->use().end()) used.emplace_back(e.n, u->second.cosMin());
    }
    std::sort(used.begin(), used.end());
    for (const auto& [n, c] : used) lp.n_used.push_back(n), lp.cos_min.push_back(c);
    if (!lp.n_used.empty()) prunePromOf(lp);
  }
  lobes.erase(std::remove_if(lobes.begin(), lobes.end(), [](const LobePrune& lp) { return lp.n_used.empty(); }), lobes.end());
  const SpanParams mode = spanConfig(best).rtl;
  narrowWidths(sc, ro, mode, full, lobes);
  OutputFiles out;
  json lobes_json = json::array();
  for (LobePrune& lp : lobes) {
    json lj = {{"lobe", toString(lp.lobe)}, {"requests", shinUseJson(*lp.recorder)}};
    lp.pruned.path = (fs::path(dir_) / ("spec_" + lp.pruned.name + ".json")).string();
    writePruned(lp, out, lj);
    lobes_json.push_back(lj);
  }
  // The material-to-address table the renderer uses (render.cpp: the PROM entry of the rounded
  // shininess).
  json materials = json::array();
  for (const Material& m : sc.materials) {
    const Lobe l = parseLobe(brdf_.empty() ? m.brdf : brdf_);
    const auto lp = std::find_if(lobes.begin(), lobes.end(), [&](const LobePrune& x) { return x.lobe == l; });
    materials.push_back({{"material", m.name},
                         {"shininess", m.shininess},
                         {"lobe", toString(l)},
                         {"address", lp != lobes.end() ? json(lp->pruned_engine->table().addressOf(std::round(m.shininess))) : json()}});
  }
  // 4. The proof: the pruned configurations in the chosen mode against the full ones, every
  // distinct specular request of that frame kept for the RTL.
  SpecEngines rec_pruned;
  for (LobePrune& lp : lobes) {
    lp.pruned_recorder = std::make_unique<RecordingSpecEngine>(*lp.pruned_engine, true);
    rec_pruned.set(lp.lobe, lp.pruned_recorder.get());
  }
  ModelSpanEngine chosen(mode);
  const RenderResult pruned = render(sc, ro, chosen, rec_pruned);
  const auto [max_diff, differ] = frameDifference(full, pruned);
  const bool image_ok = max_diff <= target_lsb_;
  say(fmt::format("pruned against full: max {} LSB ({} channel values differ)", max_diff, differ));
  json analysis = {{"scene", sc.name},
                   {"method", method_},
                   {"brdf", brdf_.empty() ? json() : json(brdf_)},
                   {"objects", sc.objects.size()},
                   {"lights", sc.lights.size()},
                   {"attributes", traits(ro.method).attributes == Attributes::Colour ? "colour" : "normal"},
                   {"counts", frameCounts(full.stats)},
                   {"triangles", triangleHistogram(full.triangles)},
                   {"lobes", lobes_json},
                   {"materials", materials}};
  // 5. The RTL (nothing to build): the chosen mode's span unit in the loop, each pruned specular
  // unit under Icarus on the frame's requests and on seeded random vectors.
  out.add((fs::path(dir_) / "analysis.json").string(), analysis.dump(1) + "\n");
  std::error_code ec;
  if (!lobes.empty()) fs::create_directories(fs::path(dir_) / "prom", ec);
  if (ec) throw std::runtime_error(fmt::format("cannot make {}: {}", (fs::path(dir_) / "prom").string(), ec.message()));
  out.commit();
  bool rtl_ok = true;
  const json rtl = rtlProof(sc, ro, uses_span ? spanConfig(best) : SpanUnitConfig{}, pruned, rec_pruned, lobes, rtl_ok);
  Hardware hw = hardware_.tools();
  const json hardware = hardwareFigures(lobes, hw);
  // The work the full frame skipped (its counts, as render --json): specular requests answered 0
  // without an evaluation, fragments rejected before shading, triangles culled before setup.
  const json counts = frameCounts(full.stats);
  json skipped = json::object();
  for (const char* k : {"spec_evaluations", "spec_at_zero", "fragments", "depth_rejected", "triangles", "culled_back",
                        "culled_outside", "culled_no_pixel"})
    skipped[k] = counts[k];
  json summary = {{"target_lsb", target_lsb_},
                  {"lane_modes", modes},
                  {"chosen_mode", uses_span ? json(best) : json()},
                  {"unused", unusedParts(ro, mode, lobes)},
                  {"dropped", dropped},
                  {"skipped", skipped},
                  {"hardware", hardware},
                  {"proof", {{"max_abs_lsb", max_diff}, {"values_differing", differ}, {"within_target", image_ok}, {"rtl", rtl}}}};
  writeFileAtomic((fs::path(dir_) / "prune.json").string(), summary.dump(1) + "\n");
  std::printf("prune %s (%s): lane mode %s; ", sc.name.c_str(), method_.c_str(), uses_span ? best.c_str() : "none");
  for (size_t k = 0; k < lobes.size(); ++k) {
    const json& lj = lobes_json[k];
    std::printf("%s lobe PROM %lld -> %lld bits", lj["lobe"].get<std::string>().c_str(),
                static_cast<long long>(lj["full"]["prom_bits"].get<int64_t>()),
                static_cast<long long>(lj["pruned"]["prom_bits"].get<int64_t>()));
    const json& full_area = hardware["spec"][lobes[k].full.name].value("area", json());
    const json& pruned_area = hardware["spec"][lobes[k].pruned.name].value("area", json());
    if (full_area.contains("ice40") && pruned_area.contains("ice40"))
      std::printf(", iCE40 %lld -> %lld LUT", static_cast<long long>(full_area["ice40"]["luts"].get<int64_t>()),
                  static_cast<long long>(pruned_area["ice40"]["luts"].get<int64_t>()));
    std::printf("; ");
  }
  std::printf("pruned image max %d LSB from the full (target %g)%s\n", max_diff, target_lsb_,
              image_ok ? "" : ": OVER THE TARGET");
  for (const json& a : hw.absent)
    if (hw.failed)
      std::fprintf(stderr, "prune: %s absent: %s\n", a["figures"].get<std::string>().c_str(), a["why"].get<std::string>().c_str());
  return image_ok && rtl_ok && !hw.failed ? kExitOk : kExitFailed;
}

}  // namespace

std::unique_ptr<Command> makePruneCmd() { return std::make_unique<PruneCmd>(); }

}  // namespace shd::cli
