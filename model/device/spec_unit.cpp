#include "device/spec_unit.h"

#include <cmath>

#include <fmt/format.h>

namespace shd {

namespace {

uint64_t lowMask(int bits) { return bits >= 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1; }

int64_t signExtend(uint64_t v, int bits) {
  const uint64_t sign = uint64_t{1} << (bits - 1);
  return static_cast<int64_t>((v ^ sign) - sign);
}

}  // namespace

PromWord encodePromWord(const SpecCoef& coef, const SpecUnitParams& p) {
  if (p.kind() == SpecKind::Table) {
    if (coef.u < 0 || coef.u > (int64_t{1} << p.SpecFracBits))
      throw std::out_of_range(fmt::format("table value code {} outside 0..{} (uQ1.{}, at most 1.0)", coef.u,
                                          int64_t{1} << p.SpecFracBits, p.SpecFracBits));
    return static_cast<uint64_t>(coef.u);
  }
  const FixedFormat cf = p.coefFormat();
  const int cw = cf.width();
  if (!cf.holds(coef.u)) throw std::out_of_range(fmt::format("coefficient code {} outside {}", coef.u, cf.str()));
  PromWord w = static_cast<uint64_t>(coef.u) & lowMask(cw);
  if (p.kind() == SpecKind::Poly && p.Degree == 3) {
    if (!cf.holds(coef.v)) throw std::out_of_range(fmt::format("coefficient code {} outside {}", coef.v, cf.str()));
    if (coef.cut < 0 || coef.cut > p.cosOne())
      throw std::out_of_range(fmt::format("cut-off code {} outside 0..{}", coef.cut, p.cosOne()));
    w |= static_cast<PromWord>(static_cast<uint64_t>(coef.v) & lowMask(cw)) << cw;
    w |= static_cast<PromWord>(static_cast<uint64_t>(coef.cut)) << (2 * cw);
  }
  return w;
}

SpecCoef decodePromWord(PromWord word, const SpecUnitParams& p) {
  const FixedFormat cf = p.coefFormat();
  const int cw = cf.width();
  SpecCoef c;
  if (p.kind() == SpecKind::Table) {
    c.u = static_cast<int64_t>(static_cast<uint64_t>(word) & lowMask(p.promWordBits()));
    return c;
  }
  const uint64_t u = static_cast<uint64_t>(word) & lowMask(cw);
  if (p.kind() != SpecKind::Poly || p.Degree == 2) {  // schlick, explog: unsigned
    c.u = static_cast<int64_t>(u);
    return c;
  }
  c.u = signExtend(u, cw);
  c.v = signExtend(static_cast<uint64_t>(word >> cw) & lowMask(cw), cw);
  c.cut = static_cast<int64_t>(static_cast<uint64_t>(word >> (2 * cw)) & lowMask(p.CosFracBits + 1));
  return c;
}

PromWord encodePiecewiseBounds(const PiecewiseCodes& q, const SpecUnitParams& p) {
  const int cw = p.CosFracBits + 1;
  if (q.segs.size() > static_cast<size_t>(p.Segments))
    throw std::out_of_range(fmt::format("{} segments, the unit holds {}", q.segs.size(), p.Segments));
  PromWord w = 0;
  for (int j = 0; j < p.Segments; ++j) {
    const int64_t b = j < static_cast<int>(q.segs.size()) ? q.segs[static_cast<size_t>(j)].B : p.cosOne() + 1;
    if (b < 0 || b > p.cosOne() + 1) throw std::out_of_range(fmt::format("segment first code {} outside 0..{}", b, p.cosOne() + 1));
    w |= static_cast<PromWord>(static_cast<uint64_t>(b)) << (j * cw);
  }
  return w;
}

std::vector<PromWord> encodePiecewiseSegments(const PiecewiseCodes& q, const SpecUnitParams& p) {
  const FixedFormat cf = p.coefFormat();
  const int eb = p.segScaleBits(), kw = cf.width();
  std::vector<PromWord> words(static_cast<size_t>(p.Segments), PromWord{0});
  for (size_t j = 0; j < q.segs.size() && j < words.size(); ++j) {
    const PiecewiseCodes::Seg& g = q.segs[j];
    if (g.e < 0 || g.e > p.CosFracBits || g.K.size() != static_cast<size_t>(p.Degree) + 1)
      throw std::out_of_range(fmt::format("segment {}: scale {} or {} coefficients do not fit the unit", j, g.e, g.K.size()));
    PromWord w = static_cast<uint64_t>(g.e);
    for (size_t i = 0; i < g.K.size(); ++i) {
      if (!cf.holds(g.K[i])) throw std::out_of_range(fmt::format("coefficient code {} outside {}", g.K[i], cf.str()));
      w |= static_cast<PromWord>(static_cast<uint64_t>(g.K[i]) & lowMask(kw)) << (eb + static_cast<int>(i) * kw);
    }
    words[j] = w;
  }
  return words;
}

PiecewiseCodes decodePiecewise(PromWord bounds, const PromWord* segs, const SpecUnitParams& p) {
  const int cw = p.CosFracBits + 1, eb = p.segScaleBits(), kw = p.coefFormat().width();
  PiecewiseCodes q;
  q.wc = p.CosFracBits;
  q.wf = p.SpecFracBits;
  q.kf = p.CoefFracBits;
  for (int j = 0; j < p.Segments; ++j) {
    PiecewiseCodes::Seg g;
    g.B = static_cast<int64_t>(static_cast<uint64_t>(bounds >> (j * cw)) & lowMask(cw));
    g.e = static_cast<int>(static_cast<uint64_t>(segs[j]) & lowMask(eb));
    for (int i = 0; i <= p.Degree; ++i)
      g.K.push_back(signExtend(static_cast<uint64_t>(segs[j] >> (eb + i * kw)) & lowMask(kw), kw));
    if (j > 0 && g.B < q.segs.back().B)
      throw std::invalid_argument(fmt::format("segment {} begins at cosine code {}, below segment {}'s {}", j, g.B, j - 1,
                                              q.segs.back().B));
    if (g.e > p.CosFracBits)
      throw std::invalid_argument(fmt::format("segment {} has the scale {}, above CosFracBits = {}", j, g.e, p.CosFracBits));
    q.segs.push_back(std::move(g));
  }
  // u = (c - B_j) 2^e must stay at most 1.0 (2^Wc) over the codes the segment is selected for.
  for (size_t j = 0; j < q.segs.size(); ++j) {
    const int64_t end = std::min(j + 1 < q.segs.size() ? q.segs[j + 1].B : p.cosOne() + 1, p.cosOne() + 1);
    const int64_t last = end - 1 - q.segs[j].B;  // C - B of the segment's last code
    if (last > 0 && (last << q.segs[j].e) > p.cosOne())
      throw std::invalid_argument(fmt::format("segment {} (codes {}..{}) with the scale {} carries u past 1.0", j,
                                              q.segs[j].B, end - 1, q.segs[j].e));
  }
  return q;
}

SpecUnitModel::SpecUnitModel(SpecUnitParams params, std::vector<PromWord> prom, std::vector<PromWord> seg)
    : p_(params), prom_(std::move(prom)), seg_(std::move(seg)) {
  p_.validate();
  if (prom_.size() != static_cast<size_t>(p_.promDepth()))
    throw std::invalid_argument(fmt::format("PROM has {} words, the unit addresses {} ({} address bits)",
                                            prom_.size(), p_.promDepth(), p_.promAddrBits()));
  const int wb = p_.promWordBits();
  for (size_t i = 0; i < prom_.size(); ++i) {
    if (wb < 128 && (prom_[i] >> wb) != 0)
      throw std::invalid_argument(fmt::format("PROM word {} has bits above its {}-bit width", i, wb));
    // A table word is f itself: above 1.0 the RTL's MUL3..MUL5 would drop the result's top bit.
    if (p_.kind() == SpecKind::Table && prom_[i] > (PromWord{1} << p_.SpecFracBits))
      throw std::invalid_argument(fmt::format("PROM word {} of the table is above 1.0 (uQ1.{})", i, p_.SpecFracBits));
    coef_.push_back(decodePromWord(prom_[i], p_));
  }
  if (p_.kind() == SpecKind::ExpLog) explog_ = makeExpLogTables(p_);
  if (seg_.size() != static_cast<size_t>(p_.segDepth()))
    throw std::invalid_argument(fmt::format("segment ROM has {} words, the unit addresses {}", seg_.size(), p_.segDepth()));
  if (p_.kind() == SpecKind::Piecewise) {
    const int sb = p_.segWordBits();
    for (size_t i = 0; i < seg_.size(); ++i)
      if (sb < 128 && (seg_[i] >> sb) != 0)
        throw std::invalid_argument(fmt::format("segment ROM word {} has bits above its {}-bit width", i, sb));
    for (size_t a = 0; a < prom_.size(); ++a) {
      try {
        pieces_.push_back(decodePiecewise(prom_[a], &seg_[a * static_cast<size_t>(p_.Segments)], p_));
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(fmt::format("PROM address {}: {}", a, e.what()));
      }
    }
  }
  reset();
}

void SpecUnitModel::checkInputs(uint32_t shin, uint32_t cos) const {
  if (shin >= static_cast<uint32_t>(p_.shinCodes()))
    throw std::out_of_range(fmt::format("shininess code {} outside 0..{}", shin, p_.shinCodes() - 1));
  if (cos >= (uint32_t{2} << p_.CosFracBits))
    throw std::out_of_range(fmt::format("cos code {} does not fit uQ1.{}", cos, p_.CosFracBits));
}

int64_t SpecUnitModel::tableIndex(int64_t c) const {
  const int t = p_.TableBits;
  return std::min<int64_t>(c >> (p_.CosFracBits - t), (int64_t{1} << t) - 1);
}

int64_t SpecUnitModel::altSpec(uint32_t shin, int64_t c) const {
  if (p_.kind() == SpecKind::Table)  // one ROM read at {shin, index}
    return static_cast<int64_t>(prom_[(static_cast<size_t>(shin) << p_.TableBits) | static_cast<size_t>(tableIndex(c))]);
  if (p_.kind() == SpecKind::ExpLog) return expLogSpec(p_, explog_, coef_[shin].u, c);
  if (p_.kind() == SpecKind::Piecewise) return pieces_[shin].eval(c);
  // Schlick: f = floor(c 2^(Cf+Wf) / (m (1 - c) + 1)), den >= 1 and f <= 1 (rtl/shd_spec_schlick.v).
  const int wc = p_.CosFracBits, cf = p_.CoefFracBits;
  const int64_t den = coef_[shin].u * ((int64_t{1} << wc) - c) + (int64_t{1} << (cf + wc));
  return (c << (cf + p_.SpecFracBits)) / den;
}

SpecTrace SpecUnitModel::trace(uint32_t shin, uint32_t cos) const {
  checkInputs(shin, cos);
  const SpecCoef& k = coef_[shin];
  SpecTrace t;
  // RG2: N.H computed upstream may overshoot 1.0 by rounding; the unit saturates it.
  t.c = Fixed::fromRaw(std::min<int64_t>(cos, p_.cosOne()), p_.cosFormat());
  if (p_.kind() != SpecKind::Poly) {
    t.f = Fixed::fromRaw(altSpec(shin, t.c.raw()), p_.specFormat());
    return t;
  }
  t.sq = t.c * t.c;                                                      // MUL1
  t.d = t.sq - t.c;                                                      // BI + Sm1, carry-in 1
  t.dt = t.d.convert(p_.diffFormat(), Quant::Trunc, Overflow::Error);   // drop 2Wc - Df LSBs
  const Fixed u = Fixed::fromRaw(k.u, p_.coefFormat());
  if (p_.Degree == 2) {
    t.p = u * t.dt;                                                      // MUL2
  } else {
    const Fixed v = Fixed::fromRaw(k.v, p_.coefFormat());
    t.g = (u * t.c + v).convert(p_.hornerFormat(), Quant::Trunc, Overflow::Error);
    t.p = t.dt * t.g;                                                    // MUL2
  }
  // Pr keeps the product's integer bits: its range is proved in rtl/shd_spec_unit.v.
  const FixedFormat pr_fmt(true, t.p.format().int_bits, p_.SpecFracBits);
  t.pr = t.p.convert(pr_fmt, Quant::RoundHalfUp, Overflow::Error);
  const Fixed sum = t.c + t.pr;                                          // Sm2
  const Fixed one = Fixed::fromInt(1, p_.specFormat());
  Fixed f = sum.convert(p_.specFormat(), Quant::Trunc, Overflow::Saturate);  // clamp below 0
  if (f > one) f = one;                                                  // clamp above 1
  t.cut = p_.Degree == 3 && t.c.raw() < k.cut;
  t.f = t.cut ? Fixed::fromInt(0, p_.specFormat()) : f;
  return t;
}

int64_t SpecUnitModel::zeroCode(uint32_t shin) const {
  const uint32_t full = static_cast<uint32_t>(p_.lightMax());
  int64_t c = 0;
  while (c <= p_.cosOne() && evaluate(shin, static_cast<uint32_t>(c), {full, full, full}).spec == 0) ++c;
  return c - 1;
}

void SpecUnitModel::limitCosines(std::vector<uint32_t> least, std::string origin) {
  cos_least_ = std::move(least);
  cos_origin_ = std::move(origin);
}

void SpecUnitModel::refuseCosine(uint32_t shin, uint32_t cos) const {
  const double scale = std::ldexp(1.0, -p_.CosFracBits);
  if (shin >= cos_least_.size())
    throw std::invalid_argument(fmt::format("shininess code {} is beyond the {} codes {} was sized for", shin,
                                            cos_least_.size(), cos_origin_));
  throw std::invalid_argument(fmt::format(
      "cosine code {} (N.H = {:.6g}) at shininess code {} is below {} (N.H = {:.6g}), the least {} was sized for: "
      "its widths are proven for the inputs the scene reached only (shadesim prune this scene)",
      cos, cos * scale, shin, cos_least_[shin], cos_least_[shin] * scale, cos_origin_));
}

SpecOut SpecUnitModel::evaluate(uint32_t shin, uint32_t cos, const std::array<uint32_t, 3>& light) const {
  // The hot path: the same datapath as trace() on raw integers, wire by wire as in the RTL.
  // validate() bounds every intermediate to 62 bits, so int64_t holds each exactly, and
  // test_spec_unit checks evaluate() against trace() (the Fixed formulation) bit for bit.
  if (shin >= static_cast<uint32_t>(p_.shinCodes()) || cos >= (uint32_t{2} << p_.CosFracBits)) {
    checkInputs(shin, cos);  // throws the descriptive error
  }
  const int wc = p_.CosFracBits, wf = p_.SpecFracBits;
  const int64_t c = std::min<int64_t>(cos, p_.cosOne());            // RG2 saturation
  const int64_t one = int64_t{1} << wf;
  if (p_.kind() != SpecKind::Poly) return backEnd(altSpec(shin, c), light);
  const SpecCoef& k = coef_[shin];
  const int64_t dt = (c * c - (c << wc)) >> (2 * wc - p_.DiffFracBits);  // MUL1, Sm1, Trunc
  int64_t prod;                                                     // MUL2
  int prod_frac;
  if (p_.Degree == 2) {
    prod = k.u * dt;
    prod_frac = p_.CoefFracBits + p_.DiffFracBits;
  } else {
    const int64_t g = k.u * c + k.v * (int64_t{1} << wc);           // Horner, exact
    prod = (g >> (p_.CoefFracBits + wc - p_.HornerFracBits)) * dt;  // Trunc, MUL2
    prod_frac = p_.HornerFracBits + p_.DiffFracBits;
  }
  const int sh = prod_frac - wf;
  const int64_t pr = sh == 0 ? prod : (prod + (int64_t{1} << (sh - 1))) >> sh;  // RoundHalfUp
  int64_t f = (c << (wf - wc)) + pr;                                // Sm2
  f = f < 0 ? 0 : (f > one ? one : f);                              // clamp to [0, 1]
  if (p_.Degree == 3 && c < k.cut) f = 0;                           // cut-off
  return backEnd(f, light);
}

SpecOut SpecUnitModel::backEnd(int64_t f, const std::array<uint32_t, 3>& light) const {
  const int wf = p_.SpecFracBits;
  const int64_t one = int64_t{1} << wf;
  SpecOut out;
  out.valid = true;
  out.spec = static_cast<uint32_t>(f);
  for (int ch = 0; ch < 3; ++ch) {
    if (light[ch] > p_.lightMax())
      throw std::out_of_range(fmt::format("light code {} does not fit {} bits", light[ch], p_.LightBits));
    // f <= 1, so round(f * L) <= L fits the light's width.          MUL3..MUL5, RoundHalfUp
    out.rgb[ch] = static_cast<uint32_t>((f * light[ch] + (one >> 1)) >> wf);
  }
  return out;
}

void SpecUnitModel::reset() {
  pipe_.assign(static_cast<size_t>(p_.latency()), Stage{});
  head_ = 0;
  out_ = SpecOut{};
  cycle_ = 0;
}

SpecOut SpecUnitModel::tick(const SpecIn& in) {
  Stage s;
  s.valid = in.valid;
  if (in.valid) s.value = evaluate(in.shin, in.cos, in.light);
  pipe_[head_] = s;
  head_ = (head_ + 1) % pipe_.size();
  const Stage& oldest = pipe_[head_];  // written latency - 1 ticks ago
  if (oldest.valid) out_ = oldest.value;
  out_.valid = oldest.valid;
  ++cycle_;
  return out_;
}

}  // namespace shd
