// What a scene uses of the units as it is rendered (not as it is declared): the specular-unit
// requests of a frame per PROM address (shininess), with the range of cosine codes and light
// codes they carry, and the sizes of the screen triangles the span unit walks. `shadesim prune`
// (docs/prune.md) sizes a configuration for one scene from these.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include <nlohmann/json.hpp>

#include "render/render.h"

namespace shd {

// The requests one PROM address received over a frame.
struct ShinUse {
  uint64_t requests = 0;
  uint32_t cos_max_lit = 0;             // the largest cosine code of a request with light
  uint32_t light_max = 0;               // the largest light code of any channel
  uint64_t unlit = 0;                   // requests whose light codes are all 0
  std::map<uint32_t, uint64_t> by_cos;  // requests per cosine code (N.H in uQ1.CosFracBits)
  uint32_t cosMin() const { return by_cos.begin()->first; }  // at least one request
  uint32_t cosMax() const { return by_cos.rbegin()->first; }
};

// A specular engine that evaluates through another (the model or the RTL) and records every
// request by address. It gives no model(): the renderer sends it every request in batches, which
// renders the same image as the model's memo (test Render.PhongFixedMemoEqualsTheBatchedRequests).
class RecordingSpecEngine final : public SpecEngine {
 public:
  // keep_inputs: also keep every distinct request (distinctRequests()).
  explicit RecordingSpecEngine(SpecEngine& inner, bool keep_inputs = false) : inner_(inner), keep_(keep_inputs) {}
  const PromTable& table() const override { return inner_.table(); }
  uint64_t evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) override;
  const std::map<uint32_t, ShinUse>& use() const { return use_; }
  const SpecUnitModel* innerModel() const { return inner_.model(); }
  // The distinct requests seen (with keep_inputs), ordered by address, cosine, then light.
  std::vector<SpecRequest> distinctRequests() const;

 private:
  SpecEngine& inner_;
  bool keep_;
  std::map<uint32_t, ShinUse> use_;      // by PROM address
  std::set<std::array<uint32_t, 5>> inputs_;  // {shin, cos, light} (keep_)
};

// {"address", "n", "requests", "unlit", "cos_code_min", "cos_code_max", "cos_code_max_lit",
// "cos_min", "cos_max", "light_code_max", "zero_code", "at_or_below_zero"} per address the
// recorder saw, in address order (cos_* as cosines: the code / 2^CosFracBits). zero_code: the
// largest cosine code up to which the unit's output f is 0 at every code (the polynomial's zero
// or its cut-off; -1 when f(0) > 0), from the inner engine's model (null without one);
// at_or_below_zero: the requests there, whose evaluation the unit could skip (its output is 0
// whatever the light).
nlohmann::json shinUseJson(const RecordingSpecEngine& rec);

// The screen triangles of a frame by area (pixels: [0,1), [1,10), ... [10^4, inf)) and by the
// pixel-centre rows they span (0, 1, 2-3, 4-7, ..., 64 and more): {"area_px": [{"from", "to",
// "count"}], "rows": [{"from", "to", "count"}], "triangles", "mean_area_px", "mean_rows"}
// ("to" null for the open class).
nlohmann::json triangleHistogram(const std::vector<ScreenTriangleInfo>& triangles);

}  // namespace shd
