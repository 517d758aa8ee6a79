#include "report/scene_use.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "device/prom.h"
#include "device/spec_unit.h"

namespace shd {

std::vector<SpecRequest> RecordingSpecEngine::distinctRequests() const {
  std::vector<SpecRequest> out;
  out.reserve(inputs_.size());
  for (const auto& k : inputs_) {
    SpecRequest r;
    r.shin = k[0];
    r.cos = k[1];
    r.light = {k[2], k[3], k[4]};
    out.push_back(r);
  }
  return out;
}

uint64_t RecordingSpecEngine::evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) {
  for (const SpecRequest& r : in) {
    if (keep_) inputs_.insert({r.shin, r.cos, r.light[0], r.light[1], r.light[2]});
    ShinUse& u = use_[r.shin];
    ++u.requests;
    ++u.by_cos[r.cos];
    const uint32_t light = std::max({r.light[0], r.light[1], r.light[2]});
    u.light_max = std::max(u.light_max, light);
    if (light == 0)
      ++u.unlit;
    else
      u.cos_max_lit = std::max(u.cos_max_lit, r.cos);
  }
  return inner_.evaluate(in, out);
}

nlohmann::json shinUseJson(const RecordingSpecEngine& rec) {
  const PromTable& t = rec.table();
  const double scale = std::ldexp(1.0, -t.unit.CosFracBits);
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [address, u] : rec.use()) {
    nlohmann::json zero, below;
    if (const SpecUnitModel* m = rec.innerModel()) {
      const int64_t z = m->zeroCode(address);
      uint64_t n = 0;
      for (const auto& [cos, count] : u.by_cos)
        if (static_cast<int64_t>(cos) <= z) n += count;
      zero = z;
      below = n;
    }
    const auto e =
        std::find_if(t.entries.begin(), t.entries.end(), [a = address](const PromEntry& p) { return p.address == a; });
    out.push_back({{"address", address},
                   {"n", e == t.entries.end() ? nlohmann::json() : nlohmann::json(e->n)},
                   {"requests", u.requests},
                   {"unlit", u.unlit},
                   {"cos_code_min", u.cosMin()},
                   {"cos_code_max", u.cosMax()},
                   {"cos_code_max_lit", u.cos_max_lit},
                   {"cos_min", u.cosMin() * scale},
                   {"cos_max", u.cosMax() * scale},
                   {"light_code_max", u.light_max},
                   {"zero_code", zero},
                   {"at_or_below_zero", below}});
  }
  return out;
}

namespace {

// Classes [from, to) of a histogram: `edges` the lower bounds, the last class open.
nlohmann::json histogram(const std::vector<double>& edges, const std::vector<uint64_t>& counts) {
  nlohmann::json h = nlohmann::json::array();
  for (size_t i = 0; i < edges.size(); ++i)
    h.push_back({{"from", edges[i]},
                 {"to", i + 1 < edges.size() ? nlohmann::json(edges[i + 1]) : nlohmann::json()},
                 {"count", counts[i]}});
  return h;
}

size_t classOf(const std::vector<double>& edges, double v) {
  size_t k = 0;
  while (k + 1 < edges.size() && v >= edges[k + 1]) ++k;
  return k;
}

}  // namespace

nlohmann::json triangleHistogram(const std::vector<ScreenTriangleInfo>& triangles) {
  const std::vector<double> area_edges = {0, 1, 10, 100, 1000, 10000};
  const std::vector<double> row_edges = {0, 1, 2, 4, 8, 16, 32, 64};
  std::vector<uint64_t> areas(area_edges.size()), rows(row_edges.size());
  double area_sum = 0, row_sum = 0;
  for (const ScreenTriangleInfo& t : triangles) {
    const auto& p = t.xy;
    const double area = 0.5 * std::fabs((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]));
    const double lo = std::min({p[0][1], p[1][1], p[2][1]}), hi = std::max({p[0][1], p[1][1], p[2][1]});
    // Pixel-centre rows y + 0.5 in [lo, hi).
    const double n_rows = std::max(0.0, std::ceil(hi - 0.5) - std::ceil(lo - 0.5));
    ++areas[classOf(area_edges, area)];
    ++rows[classOf(row_edges, n_rows)];
    area_sum += area;
    row_sum += n_rows;
  }
  const double n = static_cast<double>(triangles.size());
  return {{"triangles", triangles.size()},
          {"mean_area_px", triangles.empty() ? 0.0 : area_sum / n},
          {"mean_rows", triangles.empty() ? 0.0 : row_sum / n},
          {"area_px", histogram(area_edges, areas)},
          {"rows", histogram(row_edges, rows)}};
}

}  // namespace shd
