// libFuzzer target, differential: triangle setup through the span walk (model/raster/setup.h
// setupTriangle, model/raster/span_unit.h SpanUnitModel and walkSpanUnit) in every lane mode of
// the registry (builtinConfigNames("span")).
//
// Input (little-endian fields; past the end every field reads 0, see ByteReader):
//   u8 flags   bits 0-1: triangles - 1 (1..4); bit 2: own widths (below) instead of the
//              registry's; bit 3: coordinates as raw doubles (NaN, infinities, anything) instead
//              of int16 / 2^shift; bit 4: explicit attr_frac_bits; bit 5: the consumer drops
//              out_ready by the pattern below
//   u8 width, u8 height: the viewport, 1 + byte % 64 each (every fragment set stays small;
//              the vertices still reach the whole guard band)
//   u8 subpixel_bits: 1 + byte % 8
//   bit 2: u8 x 6 NumAttr 1 + b % 16, AttrBits 8 + b % 55, CoordBits 8 + b % 23, RemBits
//          2 + b % 59, PixBits 1 + b % (CoordBits - 1), TagBits 1 + b % 32 (the ranges of
//          SpanParams::validate; the lane layout, NumTri LanesPerTri AlignLanes, is the mode's)
//   bit 4: u8 per attribute: frac bits b % (AttrBits - 1)
//   bit 5: u32 out_ready pattern, bit (cycle % 32) (at least one bit set)
//   per triangle: u8 coordinate shift s (% 16), u8 attribute shift t (% 48), then per vertex
//          x, y (int16 / 2^s, or f64 with bit 3) and NumAttr attributes (int32 / 2^t)
// Viewport, subpixel bits and widths that RasterConfig::validate refuses, and triangles
// setupTriangle refuses (std::invalid_argument: off the guard band, non-finite, attributes that
// do not fit), are clean rejections; setup's checks come before the lane split, so every mode
// must refuse the same triangles.
//
// What must be equal, per triangle (the unit's invariants, raster/span_unit.h):
//   1. every mode against serial: the same set of fragments, each (x, y, tag, every attribute
//      code) equal; sorted by (y, x) first, since the modes hand them over in different orders;
//   2. serial against rasterizeReference (direct evaluation of the three biased edge functions
//      at every pixel centre of the viewport, the plane evaluated there, unwrapped): the same
//      set (so no gap, no double hit, nothing outside the viewport, no value wrapped);
//   3. in each mode, the cycle model (SpanUnitModel, one unit fed every triangle in turn)
//      against the functional walk (walkSpanUnit, with and without its run consumer): the same
//      fragments in the same order and the same cycle counts, and the counts follow the formula
//      cycles = 1 + row cycles + span cycles, row cycles = row_last - row_first + 1;
//   4. with back-pressure (bit 5) the cycle model hands over the same fragments in the same
//      order as without.
#include <algorithm>
#include <array>
#include <cstring>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "config/registry.h"
#include "fuzz_util.h"
#include "raster/setup.h"
#include "raster/span_unit.h"
#include "raster/span_walk.h"

namespace {

using shd::SpanFragment;
using shd::fuzz::finding;
using Tri = std::array<shd::SetupVertex, 3>;

struct Mode {
  std::string name;
  shd::SpanParams params;
};

// The registry's lane modes, serial first (the reference of property 1).
const std::vector<Mode>& modes() {
  static const std::vector<Mode> all = [] {
    std::vector<Mode> m{{"serial", shd::spanConfig("serial").rtl}};
    for (const std::string& name : shd::builtinConfigNames("span"))
      if (name != "serial") m.push_back({name, shd::spanConfig(name).rtl});
    return m;
  }();
  return all;
}

struct Input {
  shd::RasterConfig cfg;  // unit: serial's lane layout with the input's widths
  std::vector<Tri> tris;
  bool stall = false;
  uint32_t ready = ~0u;
};

double coordinate(shd::fuzz::ByteReader& in, bool raw, int shift) {
  if (!raw) return static_cast<int16_t>(in.u16()) / static_cast<double>(1 << shift);
  const uint64_t bits = in.u64();
  double d = 0;
  std::memcpy(&d, &bits, sizeof d);
  return d;
}

Input decode(const uint8_t* data, size_t size) {
  shd::fuzz::ByteReader in(data, size);
  Input x;
  const uint8_t flags = in.u8();
  x.cfg.width = 1 + in.u8() % 64;
  x.cfg.height = 1 + in.u8() % 64;
  x.cfg.subpixel_bits = 1 + in.u8() % 8;
  shd::SpanParams& p = x.cfg.unit;
  p = modes().front().params;
  if (flags & 4) {
    p.NumAttr = 1 + in.u8() % 16;
    p.AttrBits = 8 + in.u8() % 55;
    p.CoordBits = 8 + in.u8() % 23;
    p.RemBits = 2 + in.u8() % 59;
    p.PixBits = 1 + in.u8() % (p.CoordBits - 1);
    p.TagBits = 1 + in.u8() % 32;
  }
  if (flags & 16)
    for (int k = 0; k < p.NumAttr; ++k) x.cfg.attr_frac_bits.push_back(in.u8() % (p.AttrBits - 1));
  if (flags & 32) {
    x.stall = true;
    x.ready = in.u32() | 1;
  }
  const int n = 1 + (flags & 3);
  for (int t = 0; t < n; ++t) {
    const int shift = in.u8() % 16, ashift = in.u8() % 48;
    Tri tri;
    for (shd::SetupVertex& v : tri) {
      v.x = coordinate(in, (flags & 8) != 0, shift);
      v.y = coordinate(in, (flags & 8) != 0, shift);
      for (int k = 0; k < p.NumAttr; ++k)
        v.attr.push_back(static_cast<int32_t>(in.u32()) / static_cast<double>(int64_t{1} << ashift));
    }
    x.tris.push_back(tri);
  }
  return x;
}

std::string describe(const Tri& t) {
  std::string s;
  for (const shd::SetupVertex& v : t) s += fmt::format(" ({:.17g}, {:.17g})", v.x, v.y);
  return s;
}

std::string describe(const SpanFragment& f) {
  return fmt::format("tag {} pixel ({}, {}) attr [{}]", f.tag, f.x, f.y, fmt::join(f.attr.begin(), f.attr.end(), " "));
}

bool operator==(const SpanFragment& a, const SpanFragment& b) {
  return a.tag == b.tag && a.x == b.x && a.y == b.y && a.attr == b.attr;
}

std::vector<SpanFragment> sorted(std::vector<SpanFragment> f) {
  std::sort(f.begin(), f.end(), [](const SpanFragment& a, const SpanFragment& b) {
    if (a.y != b.y) return a.y < b.y;
    if (a.x != b.x) return a.x < b.x;
    return std::lexicographical_compare(a.attr.begin(), a.attr.end(), b.attr.begin(), b.attr.end());
  });
  return f;
}

// The first difference of two fragment sequences, as a finding.
void requireEqual(const std::vector<SpanFragment>& got, const std::vector<SpanFragment>& want, const std::string& what) {
  const size_t n = std::min(got.size(), want.size());
  for (size_t i = 0; i < n; ++i)
    if (!(got[i] == want[i]))
      finding(fmt::format("{}: fragment {} differs: {} vs {}", what, i, describe(got[i]), describe(want[i])));
  if (got.size() != want.size())
    finding(fmt::format("{}: {} fragments vs {} (first extra: {})", what, got.size(), want.size(),
                        describe(got.size() > n ? got[n] : want[n])));
}

// The cycle model with out_ready from the pattern (bit cycle % 32): the fragments handed over
// (valid lanes in cycles with out_ready), in order.
std::vector<SpanFragment> runStalled(shd::SpanUnitModel& unit, const shd::SpanDesc& d, uint32_t ready,
                                     const std::string& what) {
  std::vector<SpanFragment> out;
  shd::SpanIn in;
  in.desc_valid = true;
  in.desc = &d;
  shd::SpanOut o;
  bool accepted = false;
  for (uint64_t cycle = 0;; ++cycle) {
    if (cycle > (uint64_t{1} << 26)) finding(what + ": the stalled unit does not finish");
    in.out_ready = ((ready >> (cycle % 32)) & 1) != 0;
    unit.tick(in, o);
    if (!accepted) {
      accepted = o.desc_ready;
      in.desc_valid = !accepted;
      continue;
    }
    if (in.out_ready)
      for (const shd::SpanLaneOut& l : o.lane)
        if (l.valid) out.push_back({o.tag, l.x, l.y, l.attr});
    if (unit.idle()) break;
  }
  return out;
}

// Property 3 (and 4 with back-pressure) for one descriptor in one mode: the fragments.
std::vector<SpanFragment> runMode(shd::SpanUnitModel& unit, shd::SpanUnitModel& stalled, const shd::SpanDesc& d,
                                  const Input& x, const std::string& what) {
  const shd::SpanParams& p = unit.params();
  const shd::SpanRun run = shd::runSpanUnit(unit, d);
  for (const SpanFragment& f : run.fragments)
    if (f.tag != d.tag) finding(fmt::format("{}: fragment with tag {}, the descriptor's is {}", what, f.tag, d.tag));
  if (run.cycles != 1 + run.row_cycles + run.span_cycles ||
      run.row_cycles != static_cast<uint64_t>(int64_t{d.row_last} - d.row_first + 1))
    finding(fmt::format("{}: {} cycles, {} ROW, {} SPAN for rows {}..{}", what, run.cycles, run.row_cycles,
                        run.span_cycles, d.row_first, d.row_last));
  std::vector<SpanFragment> walked;
  const shd::SpanWalk walk = shd::walkSpanUnit(p, d, walked);
  requireEqual(walked, run.fragments, what + ", walk against model");
  if (walk.cycles != run.cycles || walk.row_cycles != run.row_cycles || walk.span_cycles != run.span_cycles ||
      walk.fragments != run.fragments.size())
    finding(fmt::format("{}: walk counts {}/{}/{}/{} cycles/ROW/SPAN/fragments, model {}/{}/{}/{}", what,
                        walk.cycles, walk.row_cycles, walk.span_cycles, walk.fragments, run.cycles, run.row_cycles,
                        run.span_cycles, run.fragments.size()));
  // The renderer's path: rows as runs where nothing wraps, expanded here fragment by fragment.
  std::vector<SpanFragment> runs;
  auto emit = [&](int32_t px, int32_t py, const int64_t* attr) {
    runs.push_back({d.tag, px, py, shd::AttrVec(attr, attr + p.NumAttr)});
  };
  auto emitRun = [&](const shd::RowRun& r) {
    for (int64_t i = 0; i < r.count; ++i) {
      SpanFragment f{d.tag, static_cast<int32_t>(r.x0 + i * r.dx), r.y, {}};
      for (int a = 0; a < p.NumAttr; ++a) f.attr.push_back(r.a0[a] + i * r.da[a]);
      runs.push_back(f);
    }
  };
  shd::walkSpanUnit(p, d, emit, emitRun);
  requireEqual(runs, run.fragments, what + ", walk with runs against model");
  if (x.stall) requireEqual(runStalled(stalled, d, x.ready, what), run.fragments, what + ", stalled against free");
  return run.fragments;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const Input x = decode(data, size);
  try {
    x.cfg.validate();
  } catch (const std::invalid_argument& e) {
    shd::fuzz::rejected(e);
    return 0;
  }
  // Per triangle: the serial fragments (sorted), or setup's refusal.
  std::vector<std::vector<SpanFragment>> serial(x.tris.size());
  std::vector<bool> refused(x.tris.size(), false);
  for (const Mode& m : modes()) {
    shd::RasterConfig cfg = x.cfg;
    cfg.unit.NumTri = m.params.NumTri;
    cfg.unit.LanesPerTri = m.params.LanesPerTri;
    cfg.unit.AlignLanes = m.params.AlignLanes;
    cfg.validate();  // the lane layout is valid in every mode: throws only on a finding
    shd::SpanUnitModel unit(cfg.unit), stalled(cfg.unit);
    const bool reference = &m == &modes().front();
    for (size_t t = 0; t < x.tris.size(); ++t) {
      const std::string what = fmt::format("mode {}, triangle {}{}", m.name, t, describe(x.tris[t]));
      shd::SetupResult s;
      bool threw = false;
      try {
        s = shd::setupTriangle(x.tris[t], static_cast<uint32_t>(t + 1), cfg);
      } catch (const std::invalid_argument& e) {
        if (reference) shd::fuzz::rejected(e);
        threw = true;
      }
      if (reference) refused[t] = threw;
      else if (threw != refused[t]) finding(what + (threw ? ": refused, serial took it" : ": taken, serial refused it"));
      if (threw) continue;
      const std::vector<SpanFragment> got = s.desc ? sorted(runMode(unit, stalled, *s.desc, x, what)) : std::vector<SpanFragment>{};
      if (reference) {
        serial[t] = got;
        requireEqual(got, sorted(shd::rasterizeReference(s, cfg)), what + ", against direct evaluation");
      } else {
        requireEqual(got, serial[t], what + ", against serial");
      }
    }
  }
  return 0;
}
