#include "cli/report_write.h"

#include <algorithm>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "image/compose.h"
#include "io/files.h"
#include "io/process.h"
#include "sweep/area.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace shd::cli {

const std::vector<std::string> kPlotFiles = {"error_vs_cycles.png", "error_vs_cycles.csv", "error_vs_time.png",
                                             "error_vs_time.csv",   "error_vs_area.png",   "error_vs_area.csv"};

namespace {

constexpr const char* kNotApplicable = "—";
const std::vector<std::string> kAreaFigures = {"luts", "ffs", "dsps", "brams"};

// A JSON value at a path of keys, null where a key is missing.
using Path = std::vector<std::string>;
const json& at(const json& j, const Path& path) {
  static const json null;
  const json* p = &j;
  for (const std::string& k : path) {
    if (!p->is_object() || !p->contains(k)) return null;
    p = &(*p)[k];
  }
  return *p;
}

// A number with `decimals` decimals (scaled first), or "—" for null.
std::string num(const json& v, int decimals, double scale = 1) {
  if (v.is_null()) return kNotApplicable;
  if (decimals == 0 && v.is_number_integer()) return v.dump();
  return fmt::format("{:.{}f}", v.get<double>() * scale, decimals);
}

// A CSV cell: a number or boolean as JSON writes it (every digit), a string as itself, null empty.
std::string csvCell(const json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return v.get<std::string>();
  if (v.is_array()) {
    std::string s;
    for (const json& e : v) s += (s.empty() ? "" : "+") + csvCell(e);
    return s;
  }
  return v.dump();
}

std::vector<std::string> targetsOf(const json& report) {
  const json& t = at(report, {"options", "synth_targets"});
  return t.is_array() ? t.get<std::vector<std::string>>() : std::vector<std::string>{};
}

// The place-and-route devices: (name, "UP5K"), empty when nothing was placed.
std::vector<std::pair<std::string, std::string>> devicesOf(const json& report) {
  std::vector<std::pair<std::string, std::string>> v;
  const json& d = at(report, {"options", "pnr_devices"});
  if (d.is_array())
    for (const json& e : d) {
      std::string title = e["title"].get<std::string>();
      if (title.rfind("iCE40", 0) == 0) title = title.substr(5);
      v.push_back({e["name"].get<std::string>(), title});
    }
  return v;
}

// The distinct values of a key over the rows that pass `keep`, in row order.
std::vector<std::string> distinct(const json& rows, const char* key, const std::function<bool(const json&)>& keep) {
  std::vector<std::string> v;
  for (const json& r : rows)
    if (keep(r) && std::find(v.begin(), v.end(), r[key].get<std::string>()) == v.end())
      v.push_back(r[key].get<std::string>());
  return v;
}

// A Markdown table row.
std::string mdRow(const std::vector<std::string>& cells) { return "| " + fmt::format("{}", fmt::join(cells, " | ")) + " |\n"; }

std::string mdHeader(const std::vector<std::string>& cells) {
  return mdRow(cells) + mdRow(std::vector<std::string>(cells.size(), "---"));
}

// One column of a lobe's table: its header and its cell of a row (first: the method's first
// mode, where the error figures are shown; the image is the same in every mode).
struct MdColumn {
  std::string header;
  std::function<std::string(const json& row, bool first)> cell;
};

std::vector<MdColumn> lobeColumns(const json& report) {
  auto err = [](const Path& path, int decimals, double scale = 1) {
    return [path, decimals, scale](const json& r, bool first) {
      if (!first) return std::string();
      const bool highlight = path.front() == "highlight";
      if (highlight && at(r, {"highlight", "pixels"}).get<uint64_t>() == 0) return std::string(kNotApplicable);
      const json& v = at(r, path);
      return v.is_null() ? std::string("∞") : num(v, decimals, scale);  // psnr_db null: equal images
    };
  };
  auto val = [](const Path& path, int decimals) {
    return [path, decimals](const json& r, bool) { return num(at(r, path), decimals); };
  };
  std::vector<MdColumn> c = {
      {"method", [](const json& r, bool) { return "`" + r["method"].get<std::string>() + "`"; }},
      {"mode", [](const json& r, bool) { return r["mode"].get<std::string>(); }},
      {"max LSB", err({"metrics", "max_abs_lsb"}, 2)},
      {"RMSE LSB", err({"metrics", "rmse_lsb"}, 3)},
      {"PSNR dB", err({"metrics", "psnr_db"}, 2)},
      {"> 1 LSB %", err({"metrics", "share_over_1lsb"}, 2, 100)},
      {"hl max LSB", err({"highlight", "max_abs_lsb"}, 2)},
      {"hl RMSE LSB", err({"highlight", "rmse_lsb"}, 3)},
      {"hl > 1 LSB %", err({"highlight", "share_over_1lsb"}, 2, 100)},
      {"model ms", val({"ms"}, 2)},
      {"span cycles", val({"span_cycles"}, 0)},
      {"spec cycles", val({"spec_cycles"}, 0)},
      {"total cycles", val({"total_cycles"}, 0)}};
  if (at(report, {"options", "rtl"}).get<bool>()) {
    c.push_back({"RTL", [](const json& r, bool) {
                   return at(r, {"rtl", "pixel_mismatches"}).get<uint64_t>() == 0 && at(r, {"rtl", "cycles_equal"}).get<bool>()
                              ? std::string("equal")
                              : std::string("**DIFFERENT**");
                 }});
    c.push_back({"RTL ms", val({"rtl", "ms"}, 1)});
  }
  for (const auto& [d, title] : devicesOf(report)) c.push_back({title + " µs", val({"time_us", d}, 1)});
  for (const std::string& t : targetsOf(report))
    for (const std::string f : {"luts", "dsps"})
      c.push_back({fmt::format("{} {}", t == "ice40" ? "iCE40" : t, f == "luts" ? "LUT" : "DSP"),
                   [t, f](const json& r, bool) { return num(at(r, {"area", t, f}), 0); }});
  return c;
}

// The table of one lobe: a row per method and mode.
std::string lobeTable(const json& report, const std::string& lobe) {
  const std::vector<MdColumn> cols = lobeColumns(report);
  std::vector<std::string> headers;
  for (const MdColumn& c : cols) headers.push_back(c.header);
  std::string md = mdHeader(headers);
  std::string last_method;
  for (const json& r : report["rows"]) {
    if (r["lobe"] != lobe) continue;
    const bool first = r["method"] != last_method;
    last_method = r["method"].get<std::string>();
    std::vector<std::string> cells;
    for (const MdColumn& c : cols) cells.push_back(c.cell(r, first));
    md += mdRow(cells);
  }
  return md;
}

// The work the frames skipped (RenderStats, on the rows of the first lane mode: the counts are
// the same in every mode): the culled triangles and the fragments the depth test rejected (per
// method where they differ), then the specular requests at the unit's zero, a row per method and
// lobe that asks the unit.
std::string workSkipped(const json& report) {
  auto of = [](uint64_t part, uint64_t whole) {
    return whole == 0 ? fmt::format("{}", part) : fmt::format("{} of {} ({:.0f} %)", part, whole, 100.0 * part / whole);
  };
  const json& first_mode = report["options"]["modes"].at(0);
  std::vector<const json*> rows;
  for (const json& r : report["rows"])
    if (r["mode"] == first_mode) rows.push_back(&r);
  if (rows.empty()) return "";
  const json& k0 = (*rows.front())["counts"];
  std::set<std::string> depth;
  for (const json* r : rows)
    depth.insert(of((*r)["counts"]["depth_rejected"].get<uint64_t>(), (*r)["counts"]["fragments"].get<uint64_t>()));
  std::string md = fmt::format(
      "Every frame culls {} of {} triangles before setup ({} back faces, {} outside the near plane or the guard band, {} "
      "without a pixel centre); the early depth test rejects {} fragments before shading{}. Below: the specular "
      "requests at or below the unit's zero, answered 0 without an evaluation (the unit as built evaluates them, and "
      "the cycles count them).\n\n",
      k0["culled"].get<uint64_t>(), k0["triangles"].get<uint64_t>(), k0["culled_back"].get<uint64_t>(),
      k0["culled_outside"].get<uint64_t>(), k0["culled_no_pixel"].get<uint64_t>(),
      of(k0["depth_rejected"].get<uint64_t>(), k0["fragments"].get<uint64_t>()),
      depth.size() == 1 ? " with every method"
                        : fmt::format(" with {} (over all methods: {})", (*rows.front())["method"].get<std::string>(),
                                      fmt::join(depth, "; ")));
  md += mdHeader({"method", "lobe", "specular requests at the unit's zero"});
  for (const json* r : rows) {
    const json& k = (*r)["counts"];
    if (k["spec_evaluations"].get<uint64_t>() > 0)
      md += mdRow({(*r)["method"].get<std::string>(), (*r)["lobe"].get<std::string>(),
                   of(k["spec_at_zero"].get<uint64_t>(), k["spec_evaluations"].get<uint64_t>())});
  }
  return md;
}

// The units and their area.
std::string unitsTable(const json& report) {
  const std::vector<std::string> targets = targetsOf(report);
  std::vector<std::string> headers = {"unit", "configuration", "lanes", "degree"};
  for (const std::string& t : targets)
    for (const char* f : {"LUT", "FF", "DSP", "BRAM"}) headers.push_back(fmt::format("{} {}", t == "ice40" ? "iCE40" : t, f));
  std::string md = mdHeader(headers);
  for (const char* unit : {"span", "spec"})
    for (const auto& [name, u] : report["units"][unit].items()) {
      std::vector<std::string> cells = {unit, "`" + name + "`", num(at(u, {"lanes"}), 0), num(at(u, {"degree"}), 0)};
      for (const std::string& t : targets)
        for (const std::string& f : kAreaFigures) cells.push_back(num(at(u, {"area", t, f}), 0));
      md += mdRow(cells);
    }
  return md;
}

// The specular units side by side (the paper's device among the alternatives): what each costs
// (latency, PROM bits, area, fmax) and what it gives on this scene (the unit alone against cos^n
// at every cos code for the scene's shininess values; phong-fixed, which asks the unit at every
// pixel, against the reference image).
std::string specUnitsTable(const json& report) {
  std::vector<std::string> headers = {"configuration", "kind", "lobe", "latency", "PROM bits", "fixed ROM bits"};
  bool ice40 = false;
  for (const auto& [name, u] : report["units"]["spec"].items()) ice40 = ice40 || !at(u, {"area", "ice40"}).is_null();
  if (ice40)
    for (const char* f : {"LUT", "DSP", "BRAM"}) headers.push_back(fmt::format("iCE40 {}", f));
  const auto devices = devicesOf(report);
  for (const auto& [d, title] : devices) headers.push_back(title + " MHz");
  for (const char* h : {"unit max LSB", "unit peak LSB", "phong-fixed max LSB", "phong-fixed hl max LSB"})
    headers.push_back(h);
  std::string md = mdHeader(headers);
  for (const auto& [name, u] : report["units"]["spec"].items()) {
    const std::string lobe = u["lobe"].get<std::string>();
    json pf;  // the first phong-fixed row of the unit's lobe
    for (const json& r : report["rows"])
      if (r["lobe"] == lobe && r["method"] == "phong-fixed") {
        pf = r;
        break;
      }
    std::vector<std::string> cells = {"`" + name + "`", u["kind"].get<std::string>(), "`" + lobe + "`",
                                      num(u["latency"], 0), num(u["prom_bits"], 0), num(u["fixed_rom_bits"], 0)};
    if (ice40)
      for (const char* f : {"luts", "dsps", "brams"}) cells.push_back(num(at(u, {"area", "ice40", f}), 0));
    for (const auto& [d, title] : devices) cells.push_back(num(at(u, {"pnr", d, "fmax_mhz"}), 2));
    cells.push_back(num(at(u, {"scene_error", "total_max_lsb"}), 2));
    cells.push_back(num(at(u, {"scene_error", "total_peak_max_lsb"}), 2));
    cells.push_back(num(at(pf, {"metrics", "max_abs_lsb"}), 2));
    cells.push_back(num(at(pf, {"highlight", "max_abs_lsb"}), 2));
    md += mdRow(cells);
  }
  return md;
}

// Each unit's place and route per device: its fmax, or that it does not fit, with its utilisation.
std::string pnrTable(const json& report) {
  std::string md = mdHeader({"unit", "configuration", "device", "flow", "fmax MHz", "logic cells", "DSP", "BRAM", "result"});
  for (const char* unit : {"span", "spec"})
    for (const auto& [name, u] : report["units"][unit].items())
      for (const auto& [d, title] : devicesOf(report)) {
        const json& p = at(u, {"pnr", d});
        if (p.is_null()) continue;
        auto used = [&](const char* f) { return fmt::format("{} / {}", p[f].dump(), p[std::string(f) + "_total"].dump()); };
        const std::string result = p["fits"].get<bool>() ? "fmax " + p["fmax_kind"].get<std::string>()
                                                         : p["why_not"].get<std::string>();
        md += mdRow({unit, "`" + name + "`", title, "`" + p["flow"].get<std::string>() + "`", num(p["fmax_mhz"], 2),
                     used("luts"), used("dsps"), used("brams"), result});
      }
  return md;
}

std::string checksSection(const json& report) {
  const json& ch = report["checks"];
  std::string md = "## Checks\n\n";
  md += fmt::format("- Images across lane modes: {} ({} images compared with the first mode's).\n",
                    ch["images_equal_across_modes"].get<bool>() ? "equal" : "**DIFFERENT**",
                    ch["mode_comparisons"].get<uint64_t>());
  md += ch["rtl"].is_null() ? std::string("- RTL in the loop: not run (give `--rtl`).\n")
                            : fmt::format("- RTL in the loop: {} (images and cycles of every row).\n",
                                          ch["rtl"].get<bool>() ? "equal to the model" : "**DIFFERENT**");
  for (const json& f : ch["failures"]) md += "- FAILED: " + f.get<std::string>() + "\n";
  return md + "\n";
}

std::string sheetAndPlotsSections(const json& report) {
  const json& sheet = report["contact_sheet"];
  std::string md = "## Contact sheet\n\n`contact_sheet.png`: " + sheet["what"].get<std::string>() + ".\n\n";
  md += mdHeader({"position", "lobe"});
  for (size_t i = 0; i < sheet["rows"].size(); ++i)
    md += mdRow({fmt::format("row {}", i + 1), sheet["rows"][i].get<std::string>()});
  md += "\n" + mdHeader({"position", "method"});
  for (size_t i = 0; i < sheet["columns"].size(); ++i)
    md += mdRow({fmt::format("column {}", i + 1), "`" + sheet["columns"][i].get<std::string>() + "`"});
  const json& plots = report["plots"];
  md += "\n## Plots\n\n";
  if (plots["made"].get<bool>()) {
    for (const json& f : plots["files"]) md += fmt::format("- `{}`\n", f.get<std::string>());
    md += "\nEach PNG's data is the CSV beside it (scripts/plot_report.py, docs/report.md).\n\n";
  } else {
    md += "Skipped: " + plots["why"].get<std::string>() + ".\n\n";
  }
  return md;
}

}  // namespace

json notApplicable(const json& report) {
  const json& rows = report["rows"];
  json na = json::array();
  auto add = [&na](std::vector<std::string> columns, const std::string& where, const std::string& why) {
    na.push_back({{"columns", columns}, {"where", where}, {"why", why}});
  };
  const std::vector<std::string> no_hw =
      distinct(rows, "method", [](const json& r) { return r["span_cycles"].is_null(); });
  if (!no_hw.empty())
    add({"span_cycles", "spec_cycles", "total_cycles", "time_us", "area"}, fmt::format("methods {}", fmt::join(no_hw, ", ")),
        "computed per pixel in double precision, by neither unit: no hardware time and no area");
  const std::vector<std::string> no_spec = distinct(
      rows, "lobe", [](const json& r) { return !r["span_cycles"].is_null() && r["spec_cycles"].is_null(); });
  if (!no_spec.empty())
    add({"spec_cycles", "specular-unit area"}, fmt::format("lobes {}", fmt::join(no_spec, ", ")),
        "evaluated exactly, in double precision, without the specular unit (only the device lobes quadratic and "
        "cubic use it)");
  const std::vector<std::string> no_hl =
      distinct(rows, "lobe", [](const json& r) { return r["highlight"]["pixels"].get<uint64_t>() == 0; });
  if (!no_hl.empty())
    add({"highlight"}, fmt::format("lobes {}", fmt::join(no_hl, ", ")),
        fmt::format("no covered pixel's reference specular part exceeds {} LSB: the image has no highlight",
                    at(report, {"options", "highlight_lsb"}).get<double>()));
  if (!at(report, {"options", "rtl"}).get<bool>())
    add({"rtl"}, "every row", "not run: give --rtl to render every row with the verilated units as well");
  for (const json& a : at(report, {"hardware", "absent"}))
    add({a["figures"].get<std::string>()}, "every row", a["why"].get<std::string>());
  for (const auto& [d, title] : devicesOf(report)) {
    const std::vector<std::string> none = distinct(rows, "mode", [&](const json& r) {
      return !r["span_cycles"].is_null() && at(r, {"time_us", d}).is_null();
    });
    if (!none.empty())
      add({"time_us." + d}, fmt::format("lane modes {}", fmt::join(none, ", ")),
          fmt::format("a unit of the row does not fit the {} or was not placed (Place and route, Hardware)", title));
  }
  return na;
}

std::string reportCsv(const json& report) {
  const std::vector<std::string> targets = targetsOf(report);
  const bool rtl = at(report, {"options", "rtl"}).get<bool>();
  std::vector<std::pair<std::string, Path>> cols = {
      {"method", {"method"}}, {"lobe", {"lobe"}}, {"mode", {"mode"}}, {"span_config", {"span_config"}},
      {"spec_configs", {"spec_configs"}}};
  for (const char* group : {"metrics", "highlight"})
    for (const char* f : {"max_abs_lsb", "rmse_lsb", "psnr_db", "share_over_1lsb", "pixels"})
      cols.push_back({fmt::format("{}{}", group == std::string("metrics") ? "" : "highlight_", f), {group, f}});
  for (const char* f : {"ms", "frames", "span_cycles", "spec_cycles", "total_cycles", "spec_evaluations",
                        "image_equals_first_mode"})
    cols.push_back({f, {f}});
  for (const char* f : {"spec_at_zero", "depth_rejected", "fragments"}) cols.push_back({f, {"counts", f}});
  if (rtl)
    for (const char* f : {"pixel_mismatches", "cycles_equal", "ms"}) cols.push_back({fmt::format("rtl_{}", f), {"rtl", f}});
  for (const auto& [d, title] : devicesOf(report)) cols.push_back({"time_us_" + d, {"time_us", d}});
  std::string csv;
  for (size_t i = 0; i < cols.size(); ++i) csv += (i ? "," : "") + cols[i].first;
  for (const std::string& t : targets)
    for (const std::string& f : kAreaFigures) csv += fmt::format(",{}_{}", t, f);
  csv += "\n";
  for (const json& r : report["rows"]) {
    std::string line;
    for (size_t i = 0; i < cols.size(); ++i) line += (i ? "," : "") + csvCell(at(r, cols[i].second));
    for (const std::string& t : targets)
      for (const std::string& f : kAreaFigures) line += "," + csvCell(at(r, {"area", t, f}));
    csv += line + "\n";
  }
  return csv;
}

std::string reportMarkdown(const json& report) {
  const json& sc = report["scene"];
  const json& opt = report["options"];
  std::string md = fmt::format("# shadesim report: {}\n\n", sc["name"].get<std::string>());
  md += fmt::format("Made by {} with `{}`. Scene hash `{}`: {}x{} pixels; objects {}, triangles {}, lights {}. "
                    "Every figure below is formatted from `report.json`; shadesim's `docs/report.md` explains the columns.\n\n",
                    report["tool"].get<std::string>(), report["command"].get<std::string>(),
                    sc["hash"].get<std::string>(), sc["width"].get<int>(), sc["height"].get<int>(),
                    sc["objects"].get<int>(), sc["triangles"].get<uint64_t>(), sc["lights"].get<int>());
  md += fmt::format("Lane modes: {}. Model time: the median of {} frames per row. The error figures are the same in "
                    "every lane mode (the images are, checked below) and are shown on the method's first row.\n\n",
                    fmt::join(opt["modes"].get<std::vector<std::string>>(), ", "), opt["frames"].get<uint64_t>());
  for (const json& lobe : report["lobes"]) {
    const std::string name = lobe.get<std::string>();
    bool any = false;
    for (const json& r : report["rows"]) any = any || r["lobe"] == name;
    if (!any) continue;
    md += fmt::format("## Lobe {}\n\n", name == "material" ? "material (each material's own)" : "`" + name + "`");
    md += lobeTable(report, name) + "\n";
  }
  if (!report["rows"].empty()) md += "## Work skipped\n\n" + workSkipped(report) + "\n";
  md += "## Units\n\n" + unitsTable(report) + "\n";
  if (!report["units"]["spec"].empty())
    md += "## Specular units compared\n\nThe paper's device (kind poly) beside the alternatives a designer would weigh. "
          "Unit max/peak LSB: the unit alone against cos^n at every cos code, for the scene's shininess values "
          "(peak: where cos^n >= 0.5), in output LSBs at full light. phong-fixed: the image that asks the unit at "
          "every pixel, against the reference (hl: in the highlight).\n\n" +
          specUnitsTable(report) + "\n";
  if (!devicesOf(report).empty()) {
    std::vector<std::string> devices;  // as --pnr-devices chose them
    for (const json& d : report["options"]["pnr_devices"])
      devices.push_back(d["dsps"].get<bool>()
                            ? fmt::format("the {} with its DSPs (fmax an upper bound: the DSPs' own delays are not in it)",
                                          d["title"].get<std::string>())
                            : fmt::format("the {} without DSPs (every multiplier in logic cells; fmax exact)",
                                          d["title"].get<std::string>()));
    md += fmt::format("## Place and route\n\nEach unit alone by nextpnr (scripts/pnr.py) on {}. A row's time per frame "
                      "(µs) is its span cycles at the span unit's fmax plus its specular cycles at the specular "
                      "unit's.\n\n",
                      fmt::join(devices, ", and ")) +
          pnrTable(report) + "\n";
  }
  md += "## Columns that do not apply\n\n";
  for (const json& n : report["not_applicable"])
    md += fmt::format("- {} ({}): {}.\n", fmt::join(n["columns"].get<std::vector<std::string>>(), ", "),
                      n["where"].get<std::string>(), n["why"].get<std::string>());
  md += "\n## Skipped\n\n";
  if (report["skipped"].empty()) md += "Nothing: every method rendered with every lobe.\n";
  const json& skipped = report["skipped"];
  for (size_t i = 0; i < skipped.size();) {  // one line per run of one reason
    size_t k = i;
    std::set<std::string> methods, lobes;
    for (; k < skipped.size() && skipped[k]["why"] == skipped[i]["why"]; ++k) {
      methods.insert(skipped[k]["method"].get<std::string>());
      lobes.insert(skipped[k]["lobe"].get<std::string>());
    }
    auto names = [&](const char* key) {  // in the order of the entries
      std::vector<std::string> v;
      for (size_t e = i; e < k; ++e) {
        const std::string n = skipped[e][key].get<std::string>();
        const std::string shown = n == "*" ? "every method" : "`" + n + "`";
        if (std::find(v.begin(), v.end(), shown) == v.end()) v.push_back(shown);
      }
      return fmt::format("{}", fmt::join(v, ", "));
    };
    md += methods.size() == 1 || lobes.size() == 1
              ? fmt::format("- {} with {}: {}.\n", names("method"), names("lobe"), skipped[i]["why"].get<std::string>())
              : fmt::format("- {} (methods) with {} (lobes), each pair: {}.\n", names("method"), names("lobe"),
                            skipped[i]["why"].get<std::string>());
    i = k;
  }
  if (!report["warnings"].empty()) md += "\n## Warnings\n\n";
  for (const json& w : report["warnings"]) md += "- " + w.get<std::string>() + "\n";
  md += "\n" + sheetAndPlotsSections(report) + checksSection(report);
  return md;
}

ContactSheet contactSheet(const Measured& m) {
  std::vector<const Image*> tiles;
  ContactSheet sheet;
  sheet.json = {{"file", "contact_sheet.png"},
                {"what", "one row per lobe, one column per method; in each cell the image above its error heat map "
                         "(reduced), an empty cell where the pair was not rendered"},
                {"rows", json::array()},
                {"columns", json::array()}};
  for (Method meth : m.methods) sheet.json["columns"].push_back(toString(meth));
  int w = 1, h = 1;
  for (size_t g = 0; g < m.groups.size(); ++g) {
    bool any = false;
    for (size_t k = 0; k < m.methods.size(); ++k) any = any || m.images.count({g, k}) > 0;
    if (!any) continue;
    sheet.json["rows"].push_back(m.groups[g].name);
    for (size_t k = 0; k < m.methods.size(); ++k) {
      const auto it = m.images.find({g, k});
      tiles.push_back(it == m.images.end() ? nullptr : &it->second.thumb);
      if (it != m.images.end()) w = std::max(w, it->second.thumb.width), h = std::max(h, it->second.thumb.height);
    }
  }
  sheet.json["cell_width"] = w;
  sheet.json["cell_height"] = h;
  sheet.image = tileGrid(tiles, static_cast<int>(m.methods.size()), w, h, 6, Rgb{255, 255, 255}, Rgb{200, 200, 200});
  return sheet;
}

Plots makePlots(const json& report, const fs::path& tmp) {
  Plots p;
  const std::string script = findShareFile("scripts/plot_report.py");
  if (script.empty()) {
    p.json = {{"made", false}, {"why", "scripts/plot_report.py is neither in this installation nor in the source tree"}};
    return p;
  }
  // The python3 of PATH, else Debian's: the first that runs (the script needs only the standard
  // library); it draws with the gnuplot of PATH (Debian's gnuplot-nox).
  std::string python, out, err, error;
  for (const char* candidate : {"python3", "/usr/bin/python3"})
    if (python.empty() && runProcess({candidate, "-c", "pass"}, out, err, error) == 0) python = candidate;
  if (python.empty()) {
    p.json = {{"made", false},
              {"why", "no python3 runs (python3 of PATH, /usr/bin/python3); install the Debian package python3"}};
    return p;
  }
  if (const int status = runProcess({"gnuplot", "--version"}, out, err, error); status != 0) {
    p.json = {{"made", false},
              {"why", fmt::format("no gnuplot of PATH runs ({}); install the Debian package gnuplot-nox",
                                  status < 0 ? error : fmt::format("gnuplot --version: exit {}", status))}};
    return p;
  }
  fs::create_directories(tmp);
  const std::string in = (tmp / "report.json").string();
  writeFileAtomic(in, report.dump(1) + "\n");
  const int rc = runProcess({python, script, in, "-o", tmp.string()}, out, err, error);
  if (rc != 0) {
    std::string said = err.size() > 400 ? "..." + err.substr(err.size() - 400) : err;
    while (!said.empty() && said.back() == '\n') said.pop_back();
    p.json = {{"made", false}, {"why", fmt::format("{} {} failed ({}): {}", python, script,
                                                   rc < 0 ? error : fmt::format("exit {}", rc), said)}};
    return p;
  }
  json files = json::array();
  for (const std::string& f : kPlotFiles) {
    std::error_code ec;
    if (!fs::is_regular_file(tmp / f, ec)) continue;
    std::ifstream in_file(tmp / f, std::ios::binary);
    p.files.emplace_back(f, std::string(std::istreambuf_iterator<char>(in_file), std::istreambuf_iterator<char>()));
    files.push_back(f);
  }
  p.json = {{"made", true}, {"python", python}, {"files", files}};
  return p;
}

}  // namespace shd::cli
