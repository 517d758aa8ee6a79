#include "raster/span_unit.h"
#include "raster/span_walk.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include <fmt/format.h>

#include "config/params_json.h"

namespace shd {

using namespace span_detail;

void SpanParams::validate() const {
  auto need = [](bool ok, const char* name, int v, const char* rule) {
    if (!ok) throw std::invalid_argument(fmt::format("span parameter {} = {}: {}", name, v, rule));
  };
  need(NumTri == 1 || NumTri == 4, "NumTri", NumTri, "must be 1 or 4");
  need(LanesPerTri == 1 || LanesPerTri == 2 || LanesPerTri == 4 || LanesPerTri == 8, "LanesPerTri", LanesPerTri,
       "must be 1, 2, 4 or 8");
  need(AlignLanes == 0 || AlignLanes == 1, "AlignLanes", AlignLanes, "must be 0 or 1");
  need(NumAttr >= 1 && NumAttr <= static_cast<int>(kMaxAttr), "NumAttr", NumAttr, "must be in 1..16");
  need(AttrBits >= 8 && AttrBits <= 62, "AttrBits", AttrBits, "must be in 8..62");
  need(CoordBits >= 8 && CoordBits <= 30, "CoordBits", CoordBits, "must be in 8..30");
  need(RemBits >= 2 && RemBits <= 60, "RemBits", RemBits, "must be in 2..60");
  need(PixBits >= 1 && PixBits < CoordBits, "PixBits", PixBits, "must be in 1..CoordBits-1");
  need(TagBits >= 1 && TagBits <= 32, "TagBits", TagBits, "must be in 1..32");
}

namespace {

// In the vector files' order (sim/vectors/vector_file.h).
constexpr ParamMember<SpanParams> kSpanMembers[] = {
    {"NumTri", &SpanParams::NumTri},         {"LanesPerTri", &SpanParams::LanesPerTri},
    {"AlignLanes", &SpanParams::AlignLanes}, {"NumAttr", &SpanParams::NumAttr},
    {"AttrBits", &SpanParams::AttrBits},     {"CoordBits", &SpanParams::CoordBits},
    {"RemBits", &SpanParams::RemBits},       {"PixBits", &SpanParams::PixBits},
    {"TagBits", &SpanParams::TagBits}};

}  // namespace

SpanParams SpanParams::fromJson(const nlohmann::json& rtl, const std::string& where) {
  return paramsFromJson(rtl, kSpanMembers, true, where);
}

nlohmann::json SpanParams::toJson() const { return paramsToJson(*this, kSpanMembers); }

SpanUnitModel::SpanUnitModel(SpanParams p) : p_(p) {
  p_.validate();
  reset();
}

int64_t SpanUnitModel::wrapAttr(uint64_t v) const { return wrapTo(v, p_.AttrBits); }
int64_t SpanUnitModel::wrapCoord(int64_t v) const { return wrapTo(u(v), p_.CoordBits); }

void SpanUnitModel::reset() {
  state_ = State::Idle;
  e_.fill(SpanDdaState{});
  irow_.fill(0);
  icur_.fill(0);
  lo_.fill(0);
  hi_.fill(0);
  ne_.fill(false);
  cycle_ = row_cycles_ = span_cycles_ = 0;
}

void SpanUnitModel::outputs(SpanOut& o) const {
  o.desc_ready = state_ == State::Idle;
  o.out_valid = false;
  o.tag = 0;
  const size_t lanes = static_cast<size_t>(p_.lanes());
  o.lane.resize(lanes);  // no-op (no allocation) after the first cycle
  if (state_ != State::Span) {
    for (SpanLaneOut& l : o.lane) l.valid = false;
    return;
  }
  o.tag = d_.tag;
  const int L = p_.LanesPerTri;
  const size_t K = static_cast<size_t>(p_.NumAttr);
  for (int j = 0; j < p_.NumTri; ++j) {
    const size_t ju = static_cast<size_t>(j);
    const SpanLaneTri& t = d_.tri[ju];
    for (int i = 0; i < L; ++i) {
      SpanLaneOut& lane = o.lane[static_cast<size_t>(j * L + i)];
      const int64_t x = xg_ + i;  // CoordBits + 1 bits: no wrap
      lane.valid = ne_[ju] && lo_[ju] <= x && x <= hi_[ju];
      if (!lane.valid) continue;
      lane.attr.resize(K);
      laneFragment(p_, d_, t, x, wspan_, icur_.data(), i, lane.x, lane.y, lane.attr.data());
      o.out_valid = true;
    }
  }
}

SpanOut SpanUnitModel::tick(const SpanIn& in) {
  SpanOut out;
  tick(in, out);
  return out;
}

void SpanUnitModel::tick(const SpanIn& in, SpanOut& out) {
  outputs(out);
  const int L = p_.LanesPerTri;
  if (state_ == State::Row) ++row_cycles_;
  if (state_ == State::Span) ++span_cycles_;
  switch (state_) {
    case State::Idle:
      if (in.desc_valid) {
        if (in.desc == nullptr) throw std::invalid_argument("span descriptor missing");
        checkDescriptor(p_, *in.desc);
        d_ = *in.desc;
        w_ = d_.row_first;
        for (int j = 0; j < p_.NumTri; ++j)
          for (int s = 0; s < 3; ++s) {
            const SpanEdge& e = d_.tri[static_cast<size_t>(j)].edge[s];
            e_[static_cast<size_t>(j * 3 + s)] = {e.q, e.r};
          }
        std::copy(d_.iref.begin(), d_.iref.end(), irow_.begin());
        state_ = State::Row;
      }
      break;
    case State::Row: {
      bool any = false;
      int64_t xs = 0, xe = 0;
      for (int j = 0; j < p_.NumTri; ++j) {
        const size_t ju = static_cast<size_t>(j);
        int64_t lo = 0, hi = 0;
        const bool ne = laneRowBounds(d_.tri[ju], w_, &e_[ju * 3], lo, hi);
        lo_[ju] = lo;
        hi_[ju] = hi;
        ne_[ju] = ne;
        if (ne) {
          xs = any ? std::min(xs, lo) : lo;
          xe = any ? std::max(xe, hi) : hi;
          any = true;
        }
      }
      if (any) {
        xe_ = xe;
        xg_ = p_.AlignLanes ? xs - (((xs % L) + L) % L) : xs;
        for (int a = 0; a < p_.NumAttr; ++a) {
          const size_t ai = static_cast<size_t>(a);
          icur_[ai] = wrapAttr(u(irow_[ai]) + u(d_.didx[ai]) * u(xg_ - d_.xref));
        }
        wspan_ = w_;
        state_ = State::Span;
      } else {
        state_ = (w_ == d_.row_last) ? State::Idle : State::Row;
      }
      // Advance to the next row: DDA steps of the edges active here that stay active.
      for (int j = 0; j < p_.NumTri; ++j)
        stepEdges(d_.tri[static_cast<size_t>(j)], w_, &e_[static_cast<size_t>(j) * 3], p_.CoordBits);
      for (int a = 0; a < p_.NumAttr; ++a) {
        const size_t ai = static_cast<size_t>(a);
        irow_[ai] = wrapAttr(u(irow_[ai]) + u(d_.didy[ai]));
      }
      w_ = wrapCoord(w_ + 1);
      break;
    }
    case State::Span:
      if (!out.out_valid || in.out_ready) {
        if (xg_ + L > xe_) {
          state_ = (wspan_ == d_.row_last) ? State::Idle : State::Row;
        } else {
          xg_ += L;
          for (int a = 0; a < p_.NumAttr; ++a) {
            const size_t ai = static_cast<size_t>(a);
            icur_[ai] = wrapAttr(u(icur_[ai]) + static_cast<uint64_t>(L) * u(d_.didx[ai]));
          }
        }
      }
      break;
  }
  ++cycle_;
}

SpanRun runSpanUnit(SpanUnitModel& m, const SpanDesc& d) {
  SpanRun run;
  runSpanUnit(m, d, run);
  return run;
}

void runSpanUnit(SpanUnitModel& m, const SpanDesc& d, SpanRun& run) {
  if (!m.idle()) throw std::logic_error("runSpanUnit: the unit is busy");
  run.fragments.clear();  // its capacity kept
  run.cycles = 0;
  const uint64_t rows0 = m.rowCycles(), spans0 = m.spanCycles();
  SpanIn in;
  in.desc_valid = true;
  in.desc = &d;
  in.out_ready = true;
  bool accepted = false;
  SpanOut o;  // reused: no allocation per cycle
  for (;;) {
    m.tick(in, o);
    ++run.cycles;
    if (!accepted) {
      accepted = o.desc_ready;
      in.desc_valid = false;
      continue;
    }
    for (const SpanLaneOut& l : o.lane)
      if (l.valid) run.fragments.push_back({o.tag, l.x, l.y, l.attr});
    if (m.idle()) break;
  }
  run.valid_lanes = run.fragments.size();
  run.row_cycles = m.rowCycles() - rows0;
  run.span_cycles = m.spanCycles() - spans0;
}

SpanWalk walkSpanUnit(const SpanParams& p, const SpanDesc& d, std::vector<SpanFragment>& out) {
  SpanFragment f;
  f.tag = d.tag;
  f.attr.resize(static_cast<size_t>(p.NumAttr));
  return walkSpanUnit(p, d, [&](int32_t x, int32_t y, const int64_t* attr) {
    f.x = x;
    f.y = y;
    std::copy(attr, attr + p.NumAttr, f.attr.begin());
    out.push_back(f);
  });
}

}  // namespace shd
