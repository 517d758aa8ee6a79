#include "raster/span_unit.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace shd {

const char* toString(SpanMode m) {
  switch (m) {
    case SpanMode::Serial: return "serial";
    case SpanMode::EvenOdd: return "evenodd";
    case SpanMode::Seg2: return "seg2";
    case SpanMode::Seg4: return "seg4";
    case SpanMode::Seg8: return "seg8";
    case SpanMode::Sierpinski: return "sierpinski";
  }
  return "?";
}

std::vector<SpanMode> allSpanModes() {
  return {SpanMode::Serial, SpanMode::EvenOdd, SpanMode::Seg2, SpanMode::Seg4, SpanMode::Seg8, SpanMode::Sierpinski};
}

SpanMode parseSpanMode(const std::string& s) {
  for (SpanMode m : allSpanModes())
    if (s == toString(m)) return m;
  throw std::invalid_argument(
      fmt::format("unknown span mode '{}' (expected serial, evenodd, seg2, seg4, seg8 or sierpinski)", s));
}

SpanParams SpanParams::forMode(SpanMode m) {
  SpanParams p;
  switch (m) {
    case SpanMode::Serial: break;
    case SpanMode::EvenOdd: p.LanesPerTri = 2, p.AlignLanes = 1; break;
    case SpanMode::Seg2: p.LanesPerTri = 2; break;
    case SpanMode::Seg4: p.LanesPerTri = 4; break;
    case SpanMode::Seg8: p.LanesPerTri = 8; break;
    case SpanMode::Sierpinski: p.NumTri = 4; break;
  }
  return p;
}

SpanMode SpanParams::mode() const {
  for (SpanMode m : allSpanModes()) {
    const SpanParams f = forMode(m);
    if (f.NumTri == NumTri && f.LanesPerTri == LanesPerTri && f.AlignLanes == AlignLanes) return m;
  }
  throw std::invalid_argument(fmt::format("no span mode has NumTri {} LanesPerTri {} AlignLanes {}", NumTri,
                                          LanesPerTri, AlignLanes));
}

void SpanParams::validate() const {
  auto need = [](bool ok, const char* name, int v, const char* rule) {
    if (!ok) throw std::invalid_argument(fmt::format("span parameter {} = {}: {}", name, v, rule));
  };
  need(NumTri == 1 || NumTri == 4, "NumTri", NumTri, "must be 1 or 4");
  need(LanesPerTri == 1 || LanesPerTri == 2 || LanesPerTri == 4 || LanesPerTri == 8, "LanesPerTri", LanesPerTri,
       "must be 1, 2, 4 or 8");
  need(AlignLanes == 0 || AlignLanes == 1, "AlignLanes", AlignLanes, "must be 0 or 1");
  need(NumAttr >= 1 && NumAttr <= 16, "NumAttr", NumAttr, "must be in 1..16");
  need(AttrBits >= 8 && AttrBits <= 62, "AttrBits", AttrBits, "must be in 8..62");
  need(CoordBits >= 8 && CoordBits <= 30, "CoordBits", CoordBits, "must be in 8..30");
  need(RemBits >= 2 && RemBits <= 60, "RemBits", RemBits, "must be in 2..60");
  need(PixBits >= 1 && PixBits < CoordBits, "PixBits", PixBits, "must be in 1..CoordBits-1");
  need(TagBits >= 1 && TagBits <= 32, "TagBits", TagBits, "must be in 1..32");
  mode();
}

namespace {

// Two's complement wrap to `bits` (< 64) bits: the value mod 2^bits, sign-extended. The
// callers form sums and products in uint64_t, which is exact mod 2^64 and so mod 2^bits.
int64_t wrapTo(uint64_t v, int bits) {
  const int sh = 64 - bits;
  return static_cast<int64_t>(v << sh) >> sh;  // arithmetic shift: defined on GCC/Clang, C++20
}

uint64_t u(int64_t v) { return static_cast<uint64_t>(v); }

}  // namespace

SpanUnitModel::SpanUnitModel(SpanParams p) : p_(p) {
  p_.validate();
  reset();
}

int64_t SpanUnitModel::wrapAttr(uint64_t v) const { return wrapTo(v, p_.AttrBits); }
int64_t SpanUnitModel::wrapCoord(int64_t v) const { return wrapTo(u(v), p_.CoordBits); }

void SpanUnitModel::reset() {
  state_ = State::Idle;
  e_.assign(static_cast<size_t>(p_.NumTri) * 3, EdgeState{});
  irow_.assign(static_cast<size_t>(p_.NumAttr), 0);
  icur_.assign(static_cast<size_t>(p_.NumAttr), 0);
  lo_.assign(static_cast<size_t>(p_.NumTri), 0);
  hi_.assign(static_cast<size_t>(p_.NumTri), 0);
  ne_.assign(static_cast<size_t>(p_.NumTri), false);
  cycle_ = row_cycles_ = span_cycles_ = 0;
}

void SpanUnitModel::outputs(SpanOut& o) const {
  o.desc_ready = state_ == State::Idle;
  o.out_valid = false;
  o.tag = 0;
  o.lane.resize(static_cast<size_t>(p_.lanes()));
  for (SpanLaneOut& l : o.lane) l.valid = false;
  if (state_ != State::Span) return;
  o.tag = d_.tag;
  const int L = p_.LanesPerTri;
  for (int j = 0; j < p_.NumTri; ++j) {
    const SpanLaneTri& t = d_.tri[static_cast<size_t>(j)];
    for (int i = 0; i < L; ++i) {
      SpanLaneOut& lane = o.lane[static_cast<size_t>(j * L + i)];
      const int64_t x = xg_ + i;  // CoordBits + 1 bits: no wrap
      lane.valid = ne_[static_cast<size_t>(j)] && lo_[static_cast<size_t>(j)] <= x && x <= hi_[static_cast<size_t>(j)];
      if (!lane.valid) continue;
      const int64_t px = t.flip ? t.ox - x : x + t.ox;
      const int64_t py = t.flip ? t.oy - wspan_ : wspan_ + t.oy;
      lane.x = static_cast<int32_t>(px & ((int64_t{1} << p_.PixBits) - 1));
      lane.y = static_cast<int32_t>(py & ((int64_t{1} << p_.PixBits) - 1));
      lane.attr.resize(static_cast<size_t>(p_.NumAttr));
      for (int a = 0; a < p_.NumAttr; ++a) {
        const size_t ai = static_cast<size_t>(a);
        const uint64_t v = u(icur_[ai]) + static_cast<uint64_t>(i) * u(d_.didx[ai]);
        lane.attr[ai] = wrapAttr(t.flip ? u(t.aoff[ai]) - v : v + u(t.aoff[ai]));
      }
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
        if (in.desc == nullptr || static_cast<int>(in.desc->tri.size()) != p_.NumTri ||
            static_cast<int>(in.desc->iref.size()) != p_.NumAttr)
          throw std::invalid_argument("span descriptor does not match the unit's NumTri/NumAttr");
        if (in.desc->row_first > in.desc->row_last)  // the RTL would walk until w wraps
          throw std::invalid_argument("span descriptor without rows: setup drops such triangles");
        d_ = *in.desc;
        w_ = d_.row_first;
        for (int j = 0; j < p_.NumTri; ++j)
          for (int s = 0; s < 3; ++s) {
            const SpanEdge& e = d_.tri[static_cast<size_t>(j)].edge[s];
            e_[static_cast<size_t>(j * 3 + s)] = {e.q, e.r};
          }
        irow_ = d_.iref;
        state_ = State::Row;
      }
      break;
    case State::Row: {
      bool any = false;
      int64_t xs = 0, xe = 0;
      for (int j = 0; j < p_.NumTri; ++j) {
        const size_t ju = static_cast<size_t>(j);
        const SpanLaneTri& t = d_.tri[ju];
        int64_t lo = t.clip_x0, hi = t.clip_x1;
        for (int s = 0; s < 3; ++s) {
          const SpanEdge& e = t.edge[s];
          if (w_ < e.row_first || w_ > e.row_last) continue;
          const int64_t q = e_[static_cast<size_t>(j * 3 + s)].q;
          if (e.right) hi = std::min(hi, -q);
          else lo = std::max(lo, q);
        }
        const bool ne = t.row_first <= w_ && w_ <= t.row_last && lo <= hi;
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
        for (int s = 0; s < 3; ++s) {
          const SpanEdge& e = d_.tri[static_cast<size_t>(j)].edge[s];
          if (w_ < e.row_first || w_ >= e.row_last) continue;
          EdgeState& st = e_[static_cast<size_t>(j * 3 + s)];
          const int64_t r = st.r - e.m;
          if (r < 0) {
            st.r = r + e.div;
            st.q = wrapCoord(st.q + e.k + 1);
          } else {
            st.r = r;
            st.q = wrapCoord(st.q + e.k);
          }
        }
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
  if (!m.idle()) throw std::logic_error("runSpanUnit: the unit is busy");
  SpanRun run;
  const uint64_t rows0 = m.rowCycles(), spans0 = m.spanCycles();
  SpanIn in;
  in.desc_valid = true;
  in.desc = &d;
  in.out_ready = true;
  bool accepted = false;
  for (;;) {
    const SpanOut o = m.tick(in);
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
  return run;
}

}  // namespace shd
