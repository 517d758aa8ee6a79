#include "device/prom.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <functional>

#include <fmt/format.h>

#include "io/text.h"

namespace shd {

namespace {

double parseNumber(std::string_view tok, std::string_view whole) {
  const std::string s(tok);
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || errno != 0 || !std::isfinite(v))
    throw std::invalid_argument(fmt::format("n '{}': '{}' is not a number", whole, tok));
  return v;
}

using Quantise = std::function<int64_t(double, const char*, double)>;

void fillPolyEntry(PromEntry& e, const PromRequest& req, const SpecUnitParams& unit, const Quantise& quantise) {
  e.approx = fitApprox(req.fit, unit.Degree, e.n, req.level);
  if (unit.Degree == 2) {
    e.u_real = e.approx.a;
    e.code.u = quantise(e.u_real, "a", e.n);
  } else {
    e.u_real = e.approx.a1;
    e.v_real = e.approx.a1 + e.approx.b1;
    e.cut_real = e.approx.cut;
    e.code.u = quantise(e.u_real, "a1", e.n);
    e.code.v = quantise(e.v_real, "a1+b1", e.n);
    e.code.cut = static_cast<int64_t>(std::ceil(std::ldexp(e.cut_real, unit.CosFracBits)));
  }
}

// The table's row for e.n: bucket k holds the cos codes whose index is k (rtl/shd_spec_unit.v:
// min(c >> (Wc - T), 2^T - 1), so the last bucket also holds c = 1.0). Its value minimises the
// largest error over those codes: the midpoint of c^n at the bucket's first and last code,
// rounded half-even to uQ1.Wf. The row is words (e.address << T) .. + 2^T - 1.
void fillTableEntry(PromEntry& e, const SpecUnitParams& unit, std::vector<PromWord>& words) {
  const int t = unit.TableBits, shift = unit.CosFracBits - t;
  const size_t buckets = size_t{1} << t;
  std::vector<double> values(buckets);
  for (size_t k = 0; k < buckets; ++k) {
    const int64_t first = static_cast<int64_t>(k) << shift;
    const int64_t last = k + 1 == buckets ? unit.cosOne() : first + (int64_t{1} << shift) - 1;
    values[k] = 0.5 * (std::pow(std::ldexp(static_cast<double>(first), -unit.CosFracBits), e.n) +
                       std::pow(std::ldexp(static_cast<double>(last), -unit.CosFracBits), e.n));
    SpecCoef code;
    code.u = Fixed::fromDouble(values[k], unit.specFormat(), Quant::RoundHalfEven, Overflow::Error).raw();
    words[(static_cast<size_t>(e.address) << t) | k] = encodePromWord(code, unit);
  }
  e.approx = Approx::stepTable(std::move(values));
  e.u_real = std::nan("");  // no single stored quantity: the row's reals are e.approx.table
}

// The piecewise kind: the minimax segments of c^n, in the unit's integers (approx/piecewise.h);
// the first codes go to the PROM word, the scales and coefficients to the segment ROM words
// {address, 0 .. Segments-1}.
void fillPiecewiseEntry(PromEntry& e, const SpecUnitParams& unit, PromTable& t) {
  PiecewiseFit fit = fitPiecewise(e.n, unit.Segments, unit.Degree);
  const PiecewiseCodes q = quantisePiecewise(fit, unit.CosFracBits, unit.SpecFracBits, unit.CoefFracBits);
  const FixedFormat cf = unit.coefFormat();
  for (const PiecewiseCodes::Seg& g : q.segs)
    for (int64_t k : g.K)
      if (!cf.holds(k))
        throw std::invalid_argument(fmt::format(
            "fit minimax: a segment coefficient {} at n = {} does not fit {} (range {} .. {}); widen CoefIntBits",
            std::ldexp(static_cast<double>(k), -unit.CoefFracBits), e.n, cf.str(),
            Fixed::fromRaw(cf.rawMin(), cf).toDouble(), Fixed::fromRaw(cf.rawMax(), cf).toDouble()));
  e.cut_real = fit.cut;
  e.code.cut = q.segs.front().B;
  e.u_real = std::nan("");  // the segments' reals are e.approx.pieces
  e.approx = Approx::piecewise(std::move(fit));
  t.words[e.address] = encodePiecewiseBounds(q, unit);
  const std::vector<PromWord> segs = encodePiecewiseSegments(q, unit);
  std::copy(segs.begin(), segs.end(), t.seg_words.begin() + static_cast<std::ptrdiff_t>(e.address) * unit.Segments);
}

}  // namespace

NSpec NSpec::parse(std::string_view text, bool is_list) {
  NSpec spec;
  spec.text = std::string(text);
  spec.is_list = is_list;
  if (is_list) {
    for (std::string_view tok : splitFields(text, ',')) spec.values.push_back(parseNumber(tok, text));
  } else {
    const auto parts = splitFields(text, ':');
    if (parts.size() < 2 || parts.size() > 3)
      throw std::invalid_argument(fmt::format("n range '{}': expected lo:hi or lo:hi:step", text));
    const double lo = parseNumber(parts[0], text), hi = parseNumber(parts[1], text);
    const double step = parts.size() == 3 ? parseNumber(parts[2], text) : 1.0;
    if (!(step > 0)) throw std::invalid_argument(fmt::format("n range '{}': step must be positive", text));
    if (hi < lo) throw std::invalid_argument(fmt::format("n range '{}': hi is below lo", text));
    const double count = std::floor((hi - lo) / step + 1e-9) + 1;
    if (count > 65536) throw std::invalid_argument(fmt::format("n range '{}': more than 65536 codes", text));
    for (long i = 0; i < static_cast<long>(count); ++i) spec.values.push_back(lo + static_cast<double>(i) * step);
  }
  if (spec.values.empty()) throw std::invalid_argument(fmt::format("n '{}': no values", text));
  for (double n : spec.values)
    if (!(n >= kMinShininess && n <= kMaxShininess))
      throw std::invalid_argument(
          fmt::format("n '{}': shininess {} outside [{}, {}]", text, n, kMinShininess, kMaxShininess));
  // Each n has one address: a repeated value would make the address map ambiguous.
  std::vector<double> sorted = spec.values;
  std::sort(sorted.begin(), sorted.end());
  const auto twice = std::adjacent_find(sorted.begin(), sorted.end());
  if (twice != sorted.end())
    throw std::invalid_argument(fmt::format("n '{}': shininess {} appears more than once", text, *twice));
  return spec;
}

PromRequest PromRequest::fromContent(const PromContent& c) {
  PromRequest r;
  r.fit = parseFitKind(c.fit);
  r.level = c.level;
  r.n = NSpec::parse(c.n, c.is_list);
  return r;
}

std::string PromRequest::describe() const {
  return fmt::format("fit={} level={} n{}={} ({} codes) coef-round={}", toString(fit), level,
                     n.is_list ? "-list" : "", n.text, n.values.size(), toString(coef_round));
}

int PromTable::addressOf(double n) const {
  for (const PromEntry& e : entries)
    if (e.n == n) return static_cast<int>(e.address);
  return -1;
}

int addressBitsFor(size_t count) {
  int bits = 1;
  while ((size_t{1} << bits) < count) ++bits;
  return bits;
}

void checkFitForKind(FitKind fit, const SpecUnitParams& unit) {
  bool ok = false;
  switch (unit.kind()) {
    case SpecKind::Poly: ok = fit != FitKind::Exact; break;
    case SpecKind::Piecewise: ok = fit == FitKind::Minimax; break;
    case SpecKind::Table:
    case SpecKind::Schlick:
    case SpecKind::ExpLog: ok = fit == FitKind::Exact; break;
  }
  if (!ok)
    throw std::invalid_argument(fmt::format(
        "fit {} does not apply to the {} kind (the poly kind takes inflection, level, shortcut or minimax; the "
        "piecewise kind minimax; the table, schlick and explog kinds exact)",
        toString(fit), specKindInfo(unit.kind()).name));
}

PromTable buildPromTable(const PromRequest& req, const SpecUnitParams& unit) {
  unit.validate();
  checkFitForKind(req.fit, unit);
  PromTable t;
  t.unit = unit;
  t.request = req;
  if (req.n.values.size() > static_cast<size_t>(unit.shinCodes()))
    throw std::invalid_argument(fmt::format(
        "n '{}' has {} codes but ShinBits = {} addresses only {}; use ShinBits >= {}", req.n.text,
        req.n.values.size(), unit.ShinBits, unit.shinCodes(), addressBitsFor(req.n.values.size())));
  const FixedFormat cf = unit.coefFormat();
  auto quantise = [&](double x, const char* what, double n) {
    try {
      return Fixed::fromDouble(x, cf, req.coef_round, Overflow::Error).raw();
    } catch (const std::exception&) {
      throw std::invalid_argument(fmt::format(
          "fit {}: coefficient {} = {} at n = {} does not fit {} (range {} .. {})", toString(req.fit),
          what, x, n, cf.str(), Fixed::fromRaw(cf.rawMin(), cf).toDouble(),
          Fixed::fromRaw(cf.rawMax(), cf).toDouble()));
    }
  };
  t.words.assign(static_cast<size_t>(unit.promDepth()), PromWord{0});
  t.seg_words.assign(static_cast<size_t>(unit.segDepth()), PromWord{0});
  for (size_t i = 0; i < req.n.values.size(); ++i) {
    PromEntry e;
    e.address = static_cast<uint32_t>(i);
    e.n = req.n.values[i];
    switch (unit.kind()) {
      case SpecKind::Poly: fillPolyEntry(e, req, unit, quantise); break;
      case SpecKind::Schlick:
        e.approx = Approx::schlick(e.n);
        e.u_real = e.n - 1.0;
        e.code.u = quantise(e.u_real, "m = n - 1", e.n);
        break;
      case SpecKind::ExpLog:
        e.approx = Approx::power(e.n);
        e.u_real = e.n;
        e.code.u = quantise(e.u_real, "n", e.n);
        break;
      case SpecKind::Table: fillTableEntry(e, unit, t.words); break;
      case SpecKind::Piecewise: fillPiecewiseEntry(e, unit, t); break;
    }
    if (unit.kind() != SpecKind::Table && unit.kind() != SpecKind::Piecewise) t.words[i] = encodePromWord(e.code, unit);
    t.entries.push_back(e);
  }
  return t;
}

}  // namespace shd
