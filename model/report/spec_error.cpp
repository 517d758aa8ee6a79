#include "report/spec_error.h"

#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "device/spec_unit.h"

namespace shd {

namespace {

void keepWorst(SpecErrorWorst& w, double value, double n) {
  // n = 0 before the first row (every n is at least 1): a quantity that is 0 at every n names the first.
  if (std::isfinite(value) && (value > w.value || w.n == 0)) w = {value, n};
}

}  // namespace

SpecErrorReport computeSpecError(const std::string& config, const PromTable& table,
                                 const std::function<void(size_t, size_t)>& progress,
                                 const std::vector<int64_t>& codes) {
  const auto t0 = std::chrono::steady_clock::now();
  SpecErrorReport r;
  r.config = config;
  r.table = table;
  const SpecUnitParams& p = table.unit;
  const SpecUnitModel model(p, table.words, table.seg_words);
  const double out_scale = static_cast<double>(p.lightMax());
  const uint32_t lmax = static_cast<uint32_t>(p.lightMax());
  const double f_lsb = std::ldexp(1.0, -p.SpecFracBits);
  for (const PromEntry& e : table.entries) {
    SpecErrorRow row;
    row.n = e.n;
    row.address = e.address;
    const ApproxErrorSummary s = summarizeError(e.approx, e.n);
    row.lobe = s.at("lobe");
    row.peak50 = s.at("peak50");
    row.inflection = s.at("inflection");
    const double c_peak = levelCos(e.n, 0.5);
    const size_t count = codes.empty() ? static_cast<size_t>(p.cosOne() + 1) : codes.size();
    for (size_t k = 0; k < count; ++k) {
      const int64_t code = codes.empty() ? static_cast<int64_t>(k) : codes[k];
      const double c = std::ldexp(static_cast<double>(code), -p.CosFracBits);
      const SpecOut o = model.evaluate(e.address, static_cast<uint32_t>(code), {lmax, lmax, lmax});
      const double ideal = e.approx.eval(c);
      const double exact = std::pow(c, e.n);
      const double dp = std::fabs(o.rgb[0] - out_scale * ideal);
      if (dp > row.datapath_max_lsb) {
        row.datapath_max_lsb = dp;
        row.datapath_worst_c = c;
      }
      row.datapath_max_f_lsb = std::max(row.datapath_max_f_lsb, std::fabs(o.spec * f_lsb - ideal) / f_lsb);
      const double tot = std::fabs(o.rgb[0] - out_scale * exact);
      if (tot > row.total_max_lsb) {
        row.total_max_lsb = tot;
        row.total_worst_c = c;
      }
      if (c >= c_peak) row.total_peak_max_lsb = std::max(row.total_peak_max_lsb, tot);
    }
    SpecErrorSummary& w = r.summary;
    keepWorst(w.approx_lobe_max_abs, row.lobe.max_abs, e.n);
    keepWorst(w.approx_peak_max_abs, row.peak50.max_abs, e.n);
    keepWorst(w.approx_peak_max_rel, row.peak50.max_rel, e.n);
    keepWorst(w.approx_inflection_max_abs, row.inflection.max_abs, e.n);
    keepWorst(w.approx_inflection_max_rel, row.inflection.max_rel, e.n);
    keepWorst(w.datapath_max_lsb, row.datapath_max_lsb, e.n);
    keepWorst(w.datapath_max_f_lsb, row.datapath_max_f_lsb, e.n);
    keepWorst(w.total_max_lsb, row.total_max_lsb, e.n);
    keepWorst(w.total_peak_max_lsb, row.total_peak_max_lsb, e.n);
    r.rows.push_back(row);
    if (progress) progress(r.rows.size(), table.entries.size());
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

namespace {

nlohmann::json regionJson(const RegionError& e) {
  nlohmann::json j = {{"max_abs", e.max_abs}, {"worst_abs_c", e.worst_abs_c}, {"signed_at_worst", e.signed_at_worst}};
  if (std::isfinite(e.max_rel)) {
    j["max_rel"] = e.max_rel;
    j["worst_rel_c"] = e.worst_rel_c;
  }
  return j;
}

nlohmann::json worstJson(const SpecErrorWorst& w) { return {{"value", w.value}, {"n", w.n}}; }

}  // namespace

nlohmann::json toJson(const SpecErrorReport& r) {
  const PromTable& t = r.table;
  nlohmann::json per_n = nlohmann::json::array();
  for (const SpecErrorRow& row : r.rows) {
    per_n.push_back({
        {"n", row.n},
        {"address", row.address},
        {"approx_lobe_max_abs", row.lobe.max_abs},
        {"approx_lobe_worst_c", row.lobe.worst_abs_c},
        {"approx_peak_max_abs", row.peak50.max_abs},
        {"approx_peak_max_rel", row.peak50.max_rel},
        {"approx_inflection_max_abs", row.inflection.max_abs},
        {"approx_inflection_max_rel", row.inflection.max_rel},
        {"datapath_max_lsb", row.datapath_max_lsb},
        {"datapath_worst_c", row.datapath_worst_c},
        {"datapath_max_f_lsb", row.datapath_max_f_lsb},
        {"total_max_lsb", row.total_max_lsb},
        {"total_worst_c", row.total_worst_c},
        {"total_peak_max_lsb", row.total_peak_max_lsb},
        {"regions", {{"lobe", regionJson(row.lobe)}, {"peak50", regionJson(row.peak50)},
                     {"inflection", regionJson(row.inflection)}}},
    });
  }
  const SpecErrorSummary& s = r.summary;
  return {
      {"config", r.config},
      {"rtl", t.unit.toJson()},
      {"kind", specKindInfo(t.unit.kind()).name},
      {"fit", toString(t.request.fit)},
      {"degree", t.unit.Degree},
      {"level", t.request.level},
      {"n", t.request.n.text},
      {"output_lsb", fmt::format("1/{} (unorm{} at full light)", t.unit.lightMax(), t.unit.LightBits)},
      {"per_n", per_n},
      {"summary",
       {{"approx_lobe_max_abs", worstJson(s.approx_lobe_max_abs)},
        {"approx_peak_max_abs", worstJson(s.approx_peak_max_abs)},
        {"approx_peak_max_rel", worstJson(s.approx_peak_max_rel)},
        {"approx_inflection_max_abs", worstJson(s.approx_inflection_max_abs)},
        {"approx_inflection_max_rel", worstJson(s.approx_inflection_max_rel)},
        {"datapath_max_lsb", worstJson(s.datapath_max_lsb)},
        {"datapath_max_f_lsb", worstJson(s.datapath_max_f_lsb)},
        {"total_max_lsb", worstJson(s.total_max_lsb)},
        {"total_peak_max_lsb", worstJson(s.total_peak_max_lsb)},
        {"seconds", r.seconds}}},
  };
}

std::vector<double> representativeN(const PromTable& t) {
  std::vector<double> all;
  for (const PromEntry& e : t.entries) all.push_back(e.n);
  if (all.size() <= 24) return all;
  std::vector<double> pick;
  for (double n : {1.0, 2.0, 3.0, 5.0, 8.0, 16.0, 32.0, 64.0, 100.0, 128.0, 200.0, 256.0, 500.0, 512.0, 1000.0})
    if (t.addressOf(n) >= 0) pick.push_back(n);
  if (t.addressOf(all.back()) >= 0 && (pick.empty() || pick.back() != all.back())) pick.push_back(all.back());
  return pick;
}

std::string renderSpecErrorTable(const SpecErrorReport& primary, const SpecErrorReport* compare,
                                 const std::vector<double>& show_n) {
  const PromTable& t = primary.table;
  const SpecUnitParams& p = t.unit;
  const std::string datapath =
      p.kind() == SpecKind::Poly
          ? fmt::format("degree {}, cos uQ1.{}, coefficient {}, c^2-c to {} fraction bits", p.Degree, p.CosFracBits,
                        p.coefFormat().str(), p.DiffFracBits)
      : p.kind() == SpecKind::Table
          ? fmt::format("table of 2^{} cosine buckets per n, cos uQ1.{}", p.TableBits, p.CosFracBits)
      : p.kind() == SpecKind::Schlick
          ? fmt::format("Schlick's rational with a divider, cos uQ1.{}, m = n - 1 {}", p.CosFracBits,
                        p.coefFormat().str())
      : p.kind() == SpecKind::Piecewise
          ? fmt::format("{} segments of degree {} per n, cos uQ1.{}, coefficients {}", p.Segments, p.Degree,
                        p.CosFracBits, p.coefFormat().str())
          : fmt::format("2^(n log2 c) by log and exp tables of 2^{} intervals, cos uQ1.{}, n {}", p.TableBits,
                        p.CosFracBits, p.coefFormat().str());
  std::string out = fmt::format(
      "Specular unit '{}': {}, f uQ1.{}, output unorm{}\n"
      "Approximation (a): ideal device vs cos^n, exact maxima over c in the region.\n"
      "Datapath (b) and total (c): the bit-exact unit at every cos code, in output LSBs (1/{} of full scale).\n\n",
      primary.config, datapath, p.SpecFracBits, p.LightBits, p.lightMax());
  const std::vector<const SpecErrorReport*> reports =
      compare ? std::vector<const SpecErrorReport*>{&primary, compare} : std::vector<const SpecErrorReport*>{&primary};
  for (const SpecErrorReport* r : reports) {
    out += fmt::format("fit {} {}\n", toString(r->table.request.fit),
                       r->table.request.fit == FitKind::Level ? fmt::format("(level {})", r->table.request.level) : "");
    out += fmt::format("{:>7} {:>9} | {:>9} {:>9} {:>8} | {:>9} {:>8} | {:>8} {:>7} | {:>8} {:>8} {:>9}\n", "n",
                       "coef", "lobe abs", "at c", "peak abs", "peak rel", "infl rel", "dp LSB", "dp fLSB", "tot LSB",
                       "at c", "peak LSB");
    for (double n : show_n) {
      const int addr = r->table.addressOf(n);
      if (addr < 0) continue;
      const SpecErrorRow& row = r->rows[static_cast<size_t>(addr)];
      const PromEntry& e = r->table.entries[static_cast<size_t>(addr)];
      out += fmt::format("{:>7g} {:>9.4g} | {:>9.5f} {:>9.6f} {:>8.5f} | {:>8.3f}% {:>7.3f}% | {:>8.3f} {:>7.2f} | "
                         "{:>8.2f} {:>8.6f} {:>9.2f}\n",
                         n, e.u_real, row.lobe.max_abs, row.lobe.worst_abs_c,
                         row.peak50.max_abs, 100 * row.peak50.max_rel, 100 * row.inflection.max_rel,
                         row.datapath_max_lsb, row.datapath_max_f_lsb, row.total_max_lsb, row.total_worst_c,
                         row.total_peak_max_lsb);
    }
    const SpecErrorSummary& s = r->summary;
    out += fmt::format(
        "  over all {} n ({}): lobe abs {:.5f} (n={:g}), peak rel {:.3f}% (n={:g}), inflection rel {:.3f}% (n={:g}),\n"
        "  datapath {:.3f} LSB (n={:g}) = {:.2f} f-LSB, total {:.2f} LSB (n={:g}), total near peak {:.2f} LSB "
        "(n={:g}); {:.2f} s\n\n",
        r->rows.size(), r->table.request.n.text, s.approx_lobe_max_abs.value, s.approx_lobe_max_abs.n,
        100 * s.approx_peak_max_rel.value, s.approx_peak_max_rel.n, 100 * s.approx_inflection_max_rel.value,
        s.approx_inflection_max_rel.n, s.datapath_max_lsb.value, s.datapath_max_lsb.n, s.datapath_max_f_lsb.value,
        s.total_max_lsb.value, s.total_max_lsb.n, s.total_peak_max_lsb.value, s.total_peak_max_lsb.n, r->seconds);
  }
  out +=
      "Columns: coef = a (degree 2), a1 (degree 3), m = n - 1 (schlick), n (explog), nan (table, piecewise); lobe = c in [0,1]; peak = c^n >= 0.5; infl = c from the "
      "inflection point to 1;\n"
      "dp = datapath vs ideal device (LSB of the output, fLSB of f = spec_o); tot = unit vs cos^n; peak LSB = tot "
      "where c^n >= 0.5.\n";
  return out;
}

}  // namespace shd
