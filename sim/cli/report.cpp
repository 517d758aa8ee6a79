// shadesim report: what each shading choice costs and buys on one scene. Every method with every
// lobe that applies, in every lane mode asked: the error against the double-precision reference,
// the model's time per frame, the span and specular units' cycles per frame (with --rtl checked
// on the verilated units), the yosys area of the units each row uses and, from their place and
// route on iCE40 (scripts/pnr.py), the time per frame at the clock each unit reaches; written as
// report.json, report.csv, report.md, the images, a contact sheet and the plots of
// scripts/plot_report.py into one directory (docs/report.md).
#include <algorithm>
#include <cstdio>
#include <memory>
#include <functional>
#include <filesystem>
#include <map>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "cli/command.h"
#include "cli/hardware.h"
#include "cli/render_common.h"
#include "cli/report_measure.h"
#include "report/spec_error.h"
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

class ReportCmd final : public Command {
 public:
  void add(CLI::App& app) override;
  int run(const CLI::App& app) override;

 private:
  std::string scene_ = "builtin:sphere", dir_;
  std::vector<std::string> modes_, spec_units_;
  HardwareOptions hardware_;
  std::vector<SpecUnitConfig> alt_units_;  // --spec-units, loaded
  std::vector<double> scene_n_;            // the shininess values the scene's objects use
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
  std::vector<SpecUnitConfig> altUnitConfigs() const;
  void requireRtl(const std::vector<SpanUnitConfig>& modes, const LobeConfigs& lobes) const;
  json unitsJson(const std::vector<SpanUnitConfig>& modes, const Measured& m, const LobeConfigs& lobes,
                 Hardware& hw) const;
  json reportJson(const Scene& sc, const std::vector<SpanUnitConfig>& modes, const Measured& m, json units,
                  const Hardware& hw) const;
  void write(const Measured& m, json report, const fs::path& tmp) const;
};

// The registry's specular configurations of another kind than the paper's poly.
std::vector<std::string> otherKindConfigs() {
  std::vector<std::string> names;
  for (const std::string& n : builtinConfigNames("spec"))
    if (specConfig(n).rtl.kind() != SpecKind::Poly) names.push_back(n);
  return names;
}

void ReportCmd::add(CLI::App& app) {
  app.add_option("--scene", scene_, "builtin:sphere | builtin:plane | builtin:torus | builtin:materials, a scene JSON "
                                    "file or a mesh file")
      ->default_val(scene_);
  app.add_option("-o,--output", dir_, "the report's directory (made if missing; its parent must exist)")->required();
  app.add_option("--modes", modes_, "the lane modes (span configurations), comma-separated (default: every one of the registry, serial "
                 "first: " + fmt::format("{}", fmt::join(builtinConfigNames("span"), ",")) + ")")
      ->delimiter(',');
  app.add_option("--spec-units", spec_units_,
                 "specular units of another kind than the paper's, each evaluating the quadratic lobe as a lobe "
                 "group of its own (<name>-unit): registry names or JSON files, comma-separated, or none (default: "
                 "every one of the registry: " + fmt::format("{}", fmt::join(otherKindConfigs(), ",")) + ")")
      ->delimiter(',');
  app.add_option("--bench", bench_, "frames per row of the model; the median time is reported")
      ->check(countIn(1, 1000))
      ->default_val(bench_);
  app.add_flag("--rtl", rtl_, "also render every row with the verilated span and specular units: images and cycles "
                              "must be equal");
  hardware_.add(app, "no area and no place and route: the report without yosys and nextpnr");
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
  if (!existingOrNewDir("-o", dir_, dir, " (the report is a directory of files)")) return;
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
    refuseRepeat("--modes", names, n);
    modes.push_back(spanConfigArg("--modes", n));
    // The rows and units are keyed by the configuration's name: a file may not reuse one.
    for (size_t k = 0; k + 1 < modes.size(); ++k)
      if (modes[k].name == modes.back().name)
        throw ArgError(fmt::format("--modes: {} and {} are both named {}", names[k], n, modes.back().name));
  }
  return modes;
}

std::vector<SpecUnitConfig> ReportCmd::altUnitConfigs() const {
  const std::vector<std::string> names = spec_units_.empty() ? otherKindConfigs() : spec_units_;
  if (names == std::vector<std::string>{"none"}) return {};
  std::vector<SpecUnitConfig> units;
  for (const std::string& n : names) {
    if (n.empty() || n == "none")
      throw ArgError(fmt::format("--spec-units: '{}' (name configurations comma-separated, or none alone)", n));
    units.push_back(specConfigArg("--spec-units", n));
    if (units.back().rtl.kind() == SpecKind::Poly)
      throw ArgError(fmt::format("--spec-units: {} is the paper's poly kind, already the quadratic and cubic lobes; "
                                 "name a table or schlick configuration", n));
    for (size_t k = 0; k + 1 < units.size(); ++k)
      if (units[k].name == units.back().name)
        throw ArgError(fmt::format("--spec-units: {} and {} are both named {}", names[k], n, units.back().name));
  }
  return units;
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
  for (const SpecUnitConfig& c : alt_units_) {
    try {
      requireVerilated(c);
    } catch (const std::invalid_argument& e) {
      throw ArgError(fmt::format("--rtl: specular unit {}: {}", c.ref(), e.what()));
    }
  }
}

// The hardware tools, or why there are none: --no-hardware, a cache directory that cannot be
// made, yosys or nextpnr missing. Only a bad --hardware-cache is an argument error.
// The unit against cos^n (report/spec_error.h) for the shininess values of the scene its PROM
// holds, at every cos code: what the unit alone adds to the scene's error.
json sceneSpecError(const PromTable& t, const std::vector<double>& scene_n) {
  PromTable mine = t;
  mine.entries.clear();
  for (const PromEntry& e : t.entries)
    if (std::find(scene_n.begin(), scene_n.end(), e.n) != scene_n.end()) mine.entries.push_back(e);
  if (mine.entries.empty()) return json();
  const SpecErrorSummary s = computeSpecError("", mine).summary;
  std::vector<double> n;
  for (const PromEntry& e : mine.entries) n.push_back(e.n);
  return {{"n", n},
          {"approx_lobe_max_abs", s.approx_lobe_max_abs.value},
          {"total_max_lsb", s.total_max_lsb.value},
          {"total_peak_max_lsb", s.total_peak_max_lsb.value}};
}

// Per unit configuration its parameters and, with the tools, its area and place and route (each
// computed once, cached). A failed run leaves that figure out and says why.
json ReportCmd::unitsJson(const std::vector<SpanUnitConfig>& modes, const Measured& m, const LobeConfigs& lobes,
                          Hardware& hw) const {
  json units = {{"span", json::object()}, {"spec", json::object()}};
  std::vector<HardwareJob> jobs, area_jobs;  // the place and route first: the longest jobs
  for (const SpanUnitConfig& c : modes) {
    units["span"][c.name] = {{"description", c.description}, {"rtl", c.rtl.toJson()}, {"lanes", c.rtl.lanes()}};
    const std::string what = fmt::format("span configuration {}", c.name);
    const json rtl = c.rtl.toJson();
    if (hw.synth)
      area_jobs.push_back({"span", c.name, "area", "area of " + what,
                      [rtl, t = *hw.synth] { return unitPointArea("span", rtl, {}, json::object(), t); }});
    if (hw.pnr)
      jobs.push_back({"span", c.name, "pnr", "place and route of " + what,
                      [rtl, t = *hw.pnr] { return unitPointPnr("span", rtl, {}, json::object(), t); }});
  }
  // The specular configurations a row may name, each with the lobe group it evaluates.
  std::vector<std::pair<SpecUnitConfig, std::string>> spec = {{lobes.load(Lobe::Quadratic), toString(Lobe::Quadratic)},
                                                               {lobes.load(Lobe::Cubic), toString(Lobe::Cubic)}};
  for (const SpecUnitConfig& c : alt_units_) spec.push_back({c, unitLobeGroup(c.name)});
  for (const std::string& name : m.spec_configs) {
    const auto& [c, lobe] =
        *std::find_if(spec.begin(), spec.end(), [&](const auto& u) { return u.first.name == name; });
    units["spec"][c.name] = {{"description", c.description},
                             {"rtl", c.rtl.toJson()},
                             {"kind", specKindInfo(c.rtl.kind()).name},
                             {"degree", c.rtl.kind() == SpecKind::Poly ? json(c.rtl.Degree) : json()},
                             {"latency", c.rtl.latency()},
                             {"prom_bits", c.rtl.promBits()},
                             {"fixed_rom_bits", c.rtl.fixedRomBits()},
                             {"prom", {{"fit", c.prom.fit}, {"level", c.prom.level}, {"n", c.prom.n}}},
                             {"lobe", lobe}};
    const std::string what = fmt::format("specular configuration {}", c.name);
    const PromTable* table = &promTable(c);  // kept for the process: the jobs may run after this loop
    units["spec"][c.name]["scene_error"] = sceneSpecError(*table, scene_n_);
    if (hw.synth)
      area_jobs.push_back({"spec", c.name, "area", "area of " + what, [table, t = *hw.synth] { return specPointArea(*table, t); }});
    if (hw.pnr)
      jobs.push_back({"spec", c.name, "pnr", "place and route of " + what,
                      [table, t = *hw.pnr] { return specPointPnr(*table, t); }});
  }
  jobs.insert(jobs.end(), area_jobs.begin(), area_jobs.end());
  runHardwareJobs(jobs, units, hw, [this](const std::string& s) { say(s); });
  return units;
}

// A row's area: per target, each figure summed over the span configuration and the specular
// configurations it uses. The exact methods (no span cycles) have none, nor a row whose units
// lack one.
json rowArea(const json& row, const json& units) {
  if (row["span_cycles"].is_null()) return json();
  const json& span = units["span"][row["span_config"].get<std::string>()];
  if (!span.contains("area")) return json();
  json sum = span["area"];
  for (const json& s : row["spec_configs"]) {
    const json& unit = units["spec"][s.get<std::string>()];
    if (!unit.contains("area")) return json();
    const json& spec = unit["area"];
    for (auto& [target, figures] : sum.items())
      for (auto& [k, v] : figures.items()) {
        const json& w = spec[target][k];
        v = v.is_number_integer() && w.is_number_integer() ? json(v.get<int64_t>() + w.get<int64_t>())
                                                           : json(v.get<double>() + w.get<double>());
      }
  }
  return sum;
}

// A row's time per frame in microseconds on each device placed on: the span unit's cycles
// at its fmax plus the specular unit's cycles at the least fmax of the configurations it uses
// (each unit placed alone at its own clock; not overlapped, as total_cycles). null where the row
// has no cycles, a unit was not placed, or one does not fit the device.
json rowTime(const json& row, const json& units, const std::vector<PnrDevice>& devices) {
  if (row["span_cycles"].is_null()) return json();
  json t = json::object();
  for (const PnrDevice& d : devices) {
    auto fmax = [&](const json& u) -> double {
      const json& f = u.contains("pnr") ? u["pnr"][d.name]["fmax_mhz"] : json();
      return f.is_number() ? f.get<double>() : 0.0;
    };
    const double span = fmax(units["span"][row["span_config"].get<std::string>()]);
    bool placed = span > 0;
    double spec = 0;  // the least fmax of the specular configurations
    for (const json& s : row["spec_configs"]) {
      const double f = fmax(units["spec"][s.get<std::string>()]);
      placed = placed && f > 0;
      spec = spec == 0 ? f : std::min(spec, f);
    }
    double us = placed ? row["span_cycles"].get<double>() / span : 0;
    if (placed && spec > 0) us += row["spec_cycles"].get<double>() / spec;
    t[d.name] = placed ? json(us) : json();
  }
  return t;
}

json ReportCmd::reportJson(const Scene& sc, const std::vector<SpanUnitConfig>& modes, const Measured& m, json units,
                           const Hardware& hw) const {
  const bool with_area = hw.synth.has_value(), with_pnr = hw.pnr.has_value();
  uint64_t triangles = 0;
  for (const SceneObject& o : sc.objects) triangles += o.mesh.triangles.size();
  std::vector<std::string> mode_names, lobe_names, method_names;
  for (const SpanUnitConfig& c : modes) mode_names.push_back(c.name);
  for (const LobeGroup& g : m.groups) lobe_names.push_back(g.name);
  for (Method meth : m.methods) method_names.push_back(toString(meth));
  json rows = m.rows;
  if (with_area)
    for (json& r : rows) r["area"] = rowArea(r, units);
  if (with_pnr)
    for (json& r : rows) r["time_us"] = rowTime(r, units, hw.pnr->devices);
  json devices = json::array();
  if (with_pnr)
    for (const PnrDevice& d : hw.pnr->devices) devices.push_back({{"name", d.name}, {"title", d.title}, {"dsps", d.dsps}});
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
                   {"synth_targets", with_area ? json({"ice40", "xc7"}) : json()},
                   {"pnr_devices", devices}}},
      {"hardware", {{"cache", hw.cache.empty() ? json() : json(hw.cache)}, {"absent", hw.absent}}},
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
  // A plot this report has not (no area, no place and route) is an earlier report's: removed, so
  // that the directory holds one report.
  for (const std::string& f : kPlotFiles) {
    if (std::any_of(plots.files.begin(), plots.files.end(), [&](const auto& p) { return p.first == f; })) continue;
    std::error_code ec;
    if (fs::is_regular_file(dir / f, ec) && !fs::remove(dir / f, ec))
      std::fprintf(stderr, "report: warning: cannot remove the earlier report's %s: %s\n", (dir / f).c_str(),
                   ec.message().c_str());
  }
}

int ReportCmd::run(const CLI::App&) {
  checkOutputDir();
  hardware_.check();
  const Scene sc = loadScene(scene_);
  const std::vector<SpanUnitConfig> modes = modeConfigs();
  const LobeConfigs lobes;
  alt_units_ = altUnitConfigs();
  for (const SceneObject& o : sc.objects) scene_n_.push_back(sc.materials.at(static_cast<size_t>(o.material)).shininess);
  if (rtl_) requireRtl(modes, lobes);
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
  for (const SpecUnitConfig& c : alt_units_) setup.alt_units.push_back(c.ref());
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
                  reportLobeGroups(setup.alt_units).size(), modes.size(), bench_, rtl_ ? ", and with the verilated units" : ""));
  const Measured m = measureReport(setup);
  for (const std::string& w : m.warnings) std::fprintf(stderr, "report: warning: %s\n", w.c_str());
  Hardware hw = hardware_.tools();
  json units = unitsJson(modes, m, lobes, hw);
  const json report = reportJson(sc, modes, m, std::move(units), hw);
  write(m, report, tmp);
  std::printf("report %s: %zu rows (%zu methods x lobes, %zu skipped) in %zu lane modes into %s; images across modes %s%s\n",
              sc.name.c_str(), report["rows"].size(), m.images.size(), m.skipped.size(), modes.size(), dir_.c_str(),
              report["checks"]["images_equal_across_modes"].get<bool>() ? "equal" : "DIFFERENT",
              rtl_ ? (report["checks"]["rtl"].get<bool>() ? ", RTL equal" : ", RTL DIFFERENT") : "");
  for (const json& a : hw.absent)
    if (hw.failed)
      std::fprintf(stderr, "report: %s absent: %s\n", a["figures"].get<std::string>().c_str(),
                   a["why"].get<std::string>().c_str());
  for (const std::string& f : m.failures) std::fprintf(stderr, "MISMATCH: %s\n", f.c_str());
  if (hw.failed) std::fprintf(stderr, "report: hardware figures absent (--no-hardware leaves them out on purpose)\n");
  return m.failures.empty() && !hw.failed ? kExitOk : kExitFailed;
}

}  // namespace

std::unique_ptr<Command> makeReportCmd() { return std::make_unique<ReportCmd>(); }

}  // namespace shd::cli
