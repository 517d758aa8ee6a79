// shadesim report: what each shading choice costs and buys on one scene. Every method with every
// lobe that applies, in every lane mode asked: the error against the double-precision reference,
// the model's time per frame, the span and specular units' cycles per frame (with --rtl checked
// on the verilated units), with --synth-cache the yosys area of the units each row uses; written
// as report.json, report.csv, report.md, the images, a contact sheet and the plots of
// scripts/plot_report.py into one directory (docs/report.md).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "cli/command.h"
#include "cli/report_measure.h"
#include "cli/report_write.h"
#include "cosim/render_rtl.h"
#include "device/prom_io.h"
#include "io/files.h"
#include "sweep/area.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace shd::cli {

namespace {

// The files of a report besides the images and the plots.
const std::vector<std::string> kReportFiles = {"report.json", "report.csv", "report.md", "contact_sheet.png"};
const std::vector<std::string> kPlotFiles = {"error_vs_cycles.png", "error_vs_cycles.csv", "error_vs_area.png",
                                             "error_vs_area.csv"};

class ReportCmd final : public Command {
 public:
  void add(CLI::App& app) override;
  int run(const CLI::App& app) override;

 private:
  std::string scene_ = "builtin:sphere", dir_, synth_cache_;
  std::vector<std::string> modes_;
  size_t bench_ = 5;
  bool rtl_ = false, quiet_ = false;
  double heat_scale_ = 8, highlight_lsb_ = 32;

  void say(const std::string& m) const {
    if (!quiet_) std::fprintf(stderr, "report: %s\n", m.c_str());
  }
  // -o as a path without a trailing separator ("r/" is the directory r).
  fs::path dir() const {
    const fs::path d(dir_);
    return d.has_filename() || !d.has_parent_path() ? d : d.parent_path();
  }
  // -o: an existing directory whose report files may be replaced, or a new one in an existing
  // directory (made only when the report is written). ArgError otherwise.
  void checkOutputDir() const;
  std::vector<SpanUnitConfig> modeConfigs() const;
  void requireRtl(const std::vector<SpanUnitConfig>& modes, const LobeConfigs& lobes) const;
  json unitsJson(const std::vector<SpanUnitConfig>& modes, const Measured& m, const LobeConfigs& lobes,
                 const SynthTool* synth) const;
  json reportJson(const Scene& sc, const std::vector<SpanUnitConfig>& modes, const Measured& m, json units,
                  bool with_area) const;
  void write(const Measured& m, json report, const fs::path& tmp) const;
};

void ReportCmd::add(CLI::App& app) {
  app.add_option("--scene", scene_, "builtin:sphere | builtin:plane | builtin:torus | builtin:materials, a scene JSON "
                                    "file or a mesh file")
      ->default_val(scene_);
  app.add_option("-o,--output", dir_, "the report's directory (made if missing; its parent must exist)")->required();
  app.add_option("--modes", modes_, "the lane modes (span configurations), comma-separated (default: every one of the registry, serial "
                 "first: " + fmt::format("{}", fmt::join(builtinConfigNames("span"), ",")) + ")")
      ->delimiter(',');
  app.add_option("--bench", bench_, "frames per row of the model; the median time is reported")
      ->check(countIn(1, 1000))
      ->default_val(bench_);
  app.add_flag("--rtl", rtl_, "also render every row with the verilated span and specular units: images and cycles "
                              "must be equal");
  app.add_option("--synth-cache", synth_cache_,
                 "an existing directory of synthesised areas (shared with sweep): the yosys area (iCE40, xc7) of each "
                 "unit configuration, synthesised once");
  app.add_option("--heat-scale", heat_scale_, "error (LSB) shown white in the heat maps")
      ->check(realIn(0, 255, Ends::OpenLow))
      ->default_val(heat_scale_);
  app.add_option("--highlight", highlight_lsb_, "the highlight: pixels whose reference specular part exceeds this many LSBs")
      ->check(realIn(0, 255))
      ->default_val(highlight_lsb_);
  app.add_flag("--quiet", quiet_, "no progress on stderr");
}

void ReportCmd::checkOutputDir() const {
  std::error_code ec;
  const fs::path dir = this->dir();
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw ArgError(fmt::format("-o {}: not a directory (the report is a directory of files)", dir_));
  if (!fs::exists(dir, ec)) {
    const fs::path parent = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
    if (!fs::is_directory(parent, ec))
      throw ArgError(fmt::format("-o {}: no such directory, and its parent {} is none either", dir_, parent.string()));
    return;
  }
  if (fs::exists(dir / "images", ec) && !fs::is_directory(dir / "images", ec))
    throw ArgError(fmt::format("-o {}: {} is not a directory (the report's images go there)", dir_,
                               (dir / "images").string()));
  for (const std::vector<std::string>* names : {&kReportFiles, &kPlotFiles})
    for (const std::string& f : *names) outputTarget((dir / f).string());
}

std::vector<SpanUnitConfig> ReportCmd::modeConfigs() const {
  std::vector<std::string> names = modes_;
  if (names.empty()) {  // every configuration of the registry, serial (one lane, the baseline) first
    names = builtinConfigNames("span");
    std::stable_partition(names.begin(), names.end(), [](const std::string& n) { return n == "serial"; });
  }
  std::vector<SpanUnitConfig> modes;
  for (const std::string& n : names) {
    if (n.empty()) throw ArgError("--modes: an empty entry (name the span configurations, comma-separated)");
    if (std::count(names.begin(), names.end(), n) > 1) throw ArgError(fmt::format("--modes: {} is named twice", n));
    modes.push_back(spanConfigArg("--modes", n));
    // The rows and units are keyed by the configuration's name: a file may not reuse one.
    for (size_t k = 0; k + 1 < modes.size(); ++k)
      if (modes[k].name == modes.back().name)
        throw ArgError(fmt::format("--modes: {} and {} are both named {}", names[k], n, modes.back().name));
  }
  return modes;
}

void ReportCmd::requireRtl(const std::vector<SpanUnitConfig>& modes, const LobeConfigs& lobes) const {
  for (const SpanUnitConfig& m : modes) {
    try {
      requireVerilated(m);
    } catch (const std::invalid_argument& e) {
      throw ArgError(fmt::format("--rtl: lane mode {}: {}", m.name, e.what()));
    }
  }
  for (Lobe l : {Lobe::Quadratic, Lobe::Cubic}) {
    try {
      requireVerilated(lobes.load(l));
    } catch (const std::invalid_argument& e) {
      throw ArgError(fmt::format("--rtl: the {} lobe's specular unit {}: {}", toString(l), lobes.forLobe(l), e.what()));
    }
  }
}

// Per unit configuration its parameters and, with synth, its area (synthesised once, cached).
json ReportCmd::unitsJson(const std::vector<SpanUnitConfig>& modes, const Measured& m, const LobeConfigs& lobes,
                          const SynthTool* synth) const {
  json units = {{"span", json::object()}, {"spec", json::object()}};
  for (const SpanUnitConfig& c : modes) {
    json u = {{"description", c.description}, {"rtl", c.rtl.toJson()}, {"lanes", c.rtl.lanes()}};
    if (synth) {
      say(fmt::format("area of span configuration {} (yosys, or the cache)", c.name));
      u["area"] = unitPointArea("span", c.rtl.toJson(), "", json::object(), *synth);
    }
    units["span"][c.name] = u;
  }
  for (const std::string& name : m.spec_configs) {
    const Lobe l = name == lobes.cubic ? Lobe::Cubic : Lobe::Quadratic;
    const SpecUnitConfig c = lobes.load(l);
    json u = {{"description", c.description},
              {"rtl", c.rtl.toJson()},
              {"degree", c.rtl.Degree},
              {"prom", {{"fit", c.prom.fit}, {"level", c.prom.level}, {"n", c.prom.n}}}};
    if (synth) {
      say(fmt::format("area of specular configuration {} (yosys, or the cache)", c.name));
      u["area"] = specPointArea(buildPromTable(PromRequest::fromContent(c.prom), c.rtl), *synth);
    }
    units["spec"][c.name] = u;
  }
  return units;
}

// A row's area: per target, each figure summed over the span configuration and the specular
// configurations it uses. The exact methods (no span cycles) have none.
json rowArea(const json& row, const json& units) {
  if (row["span_cycles"].is_null()) return json();
  json sum = units["span"][row["span_config"].get<std::string>()]["area"];
  for (const json& s : row["spec_configs"]) {
    const json& spec = units["spec"][s.get<std::string>()]["area"];
    for (auto& [target, figures] : sum.items())
      for (auto& [k, v] : figures.items()) {
        const json& w = spec[target][k];
        v = v.is_number_integer() && w.is_number_integer() ? json(v.get<int64_t>() + w.get<int64_t>())
                                                           : json(v.get<double>() + w.get<double>());
      }
  }
  return sum;
}

json ReportCmd::reportJson(const Scene& sc, const std::vector<SpanUnitConfig>& modes, const Measured& m, json units,
                           bool with_area) const {
  uint64_t triangles = 0;
  for (const SceneObject& o : sc.objects) triangles += o.mesh.triangles.size();
  std::vector<std::string> mode_names, lobe_names, method_names;
  for (const SpanUnitConfig& c : modes) mode_names.push_back(c.name);
  for (const LobeGroup& g : m.groups) lobe_names.push_back(g.name);
  for (Method meth : m.methods) method_names.push_back(toString(meth));
  json rows = m.rows;
  if (with_area)
    for (json& r : rows) r["area"] = rowArea(r, units);
  bool rtl_equal = true;
  for (const json& r : rows) rtl_equal = rtl_equal && (!r.contains("rtl") || (r["rtl"]["pixel_mismatches"] == 0 && r["rtl"]["cycles_equal"] == true));
  bool modes_equal = true;
  for (const json& r : rows) modes_equal = modes_equal && r["image_equals_first_mode"].get<bool>();
  json report = {
      {"format", "shadesim report 1"},
      {"tool", fmt::format("shadesim {}", SHD_VERSION)},
      {"command", commandLine()},
      {"scene", {{"name", sc.name}, {"hash", sceneContentHash(sc)}, {"width", sc.camera.width},
                 {"height", sc.camera.height}, {"objects", sc.objects.size()}, {"triangles", triangles},
                 {"lights", sc.lights.size()}}},
      {"options", {{"modes", mode_names}, {"frames", bench_}, {"rtl", rtl_}, {"highlight_lsb", highlight_lsb_},
                   {"heat_scale_lsb", heat_scale_},
                   {"synth_targets", with_area ? json({"ice40", "xc7"}) : json()}}},
      {"methods", method_names},
      {"lobes", lobe_names},
      {"units", std::move(units)},
      {"rows", std::move(rows)},
      {"skipped", m.skipped},
      {"warnings", m.warnings},
      {"checks", {{"images_equal_across_modes", modes_equal}, {"mode_comparisons", m.mode_comparisons},
                  {"rtl", rtl_ ? json(rtl_equal) : json()}, {"failures", m.failures}}}};
  report["not_applicable"] = notApplicable(report);
  return report;
}

// The plots, then every file as one set; the directory (and images/) made only now, and removed
// again if the set cannot be written.
void ReportCmd::write(const Measured& m, json report, const fs::path& tmp) const {
  const ContactSheet sheet = contactSheet(m);
  report["contact_sheet"] = sheet.json;
  say("plots (scripts/plot_report.py)");
  const Plots plots = makePlots(report, tmp / "plots");
  report["plots"] = plots.json;
  if (!plots.json["made"].get<bool>())
    std::fprintf(stderr, "report: warning: plots skipped: %s\n", plots.json["why"].get<std::string>().c_str());
  const fs::path dir = this->dir();
  OutputFiles files;
  files.add((dir / "report.json").string(), report.dump(2) + "\n");
  files.add((dir / "report.csv").string(), reportCsv(report));
  files.add((dir / "report.md").string(), reportMarkdown(report));
  files.add((dir / "contact_sheet.png").string(), encodePng("contact_sheet.png", sheet.image));
  for (const auto& [name, bytes] : plots.files) files.add((dir / name).string(), bytes);
  for (const auto& [key, c] : m.images) {
    files.add((dir / c.image_file).string(), c.image_png);
    files.add((dir / c.heat_file).string(), c.heat_png);
  }
  std::vector<fs::path> made;
  for (const fs::path& d : {dir, dir / "images"}) {
    std::error_code ec;
    if (fs::exists(d, ec)) continue;
    if (!fs::create_directory(d, ec) || ec)
      throw std::runtime_error(fmt::format("cannot make the directory {}: {}", d.string(), ec.message()));
    made.push_back(d);
  }
  try {
    files.commit();
  } catch (...) {
    std::error_code ec;
    for (auto d = made.rbegin(); d != made.rend(); ++d) fs::remove(*d, ec);  // empty: the set wrote nothing
    throw;
  }
}

int ReportCmd::run(const CLI::App& app) {
  checkOutputDir();
  const Scene sc = loadScene(scene_);
  const std::vector<SpanUnitConfig> modes = modeConfigs();
  const LobeConfigs lobes;
  if (rtl_) requireRtl(modes, lobes);
  std::optional<SynthTool> synth;
  if (app.count("--synth-cache") > 0) {
    requireDirectoryArg("--synth-cache", synth_cache_);
    synth = SynthTool{findShareFile("scripts/synth.py"), synth_cache_, "both", ""};
    if (synth->script.empty())
      throw ArgError("--synth-cache: scripts/synth.py is neither in this installation nor in the source tree");
    synth->version = synthToolVersion(synth->script);
  }
  const fs::path tmp = fs::temp_directory_path() / fmt::format("shadesim-report-{}", getpid());
  struct RemoveTmp {
    fs::path p;
    ~RemoveTmp() {
      std::error_code ec;
      fs::remove_all(p, ec);
    }
  } remove_tmp{tmp};
  ReportSetup setup;
  setup.scene = &sc;
  setup.modes = modes;
  setup.lobes = lobes;
  setup.frames = bench_;
  setup.rtl = rtl_;
  setup.quiet = quiet_;
  setup.highlight_lsb = highlight_lsb_;
  setup.heat_scale = heat_scale_;
  setup.tmp = tmp / "rtl";
  std::error_code ec;
  // An RTL disagreement is saved in the report's directory, or beside it while it is not made.
  setup.fail_dir = fs::is_directory(dir(), ec) ? dir().string()
                                              : (dir().has_parent_path() ? dir().parent_path().string() : ".");
  say(fmt::format("{}: {} methods x {} lobes x {} lane modes, {} frames each{}", sc.name, allMethods().size(),
                  reportLobeGroups().size(), modes.size(), bench_, rtl_ ? ", and with the verilated units" : ""));
  const Measured m = measureReport(setup);
  for (const std::string& w : m.warnings) std::fprintf(stderr, "report: warning: %s\n", w.c_str());
  json units = unitsJson(modes, m, lobes, synth ? &*synth : nullptr);
  const json report = reportJson(sc, modes, m, std::move(units), synth.has_value());
  write(m, report, tmp);
  std::printf("report %s: %zu rows (%zu methods x lobes, %zu skipped) in %zu lane modes into %s; images across modes %s%s\n",
              sc.name.c_str(), report["rows"].size(), m.images.size(), m.skipped.size(), modes.size(), dir_.c_str(),
              report["checks"]["images_equal_across_modes"].get<bool>() ? "equal" : "DIFFERENT",
              rtl_ ? (report["checks"]["rtl"].get<bool>() ? ", RTL equal" : ", RTL DIFFERENT") : "");
  if (m.failures.empty()) return kExitOk;
  for (const std::string& f : m.failures) std::fprintf(stderr, "MISMATCH: %s\n", f.c_str());
  return kExitFailed;
}

}  // namespace

std::unique_ptr<Command> makeReportCmd() { return std::make_unique<ReportCmd>(); }

}  // namespace shd::cli
