// Fixed-point type: exhaustive checks against exact rational arithmetic on small formats.
#include "fixed/fixed.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using shd::Fixed;
using shd::FixedFormat;
using shd::Overflow;
using shd::Quant;

namespace {

// Small formats covering signed/unsigned, m = 0..3, f = 0..3.
std::vector<FixedFormat> smallFormats() {
  std::vector<FixedFormat> v;
  for (int s = 0; s < 2; ++s)
    for (int m = 0; m <= 3; ++m)
      for (int f = 0; f <= 3; ++f) {
        FixedFormat fmt(s != 0, m, f);
        if (fmt.width() < 1 || (fmt.is_signed && m < 1)) continue;
        v.push_back(fmt);
      }
  return v;
}

// Exact reference: the value raw/2^f as a rational with denominator 2^D (D = 16 here).
constexpr int kD = 16;
int64_t scaled(int64_t raw, int frac) { return raw * (int64_t{1} << (kD - frac)); }

// Reference rounding of the rational num/2^k to an integer, independent of requantize():
// uses long division on non-negative magnitudes and sign handling.
int64_t refRound(int64_t num, int k, Quant q) {
  const int64_t den = int64_t{1} << k;
  // floor division
  int64_t fl = num / den;
  if ((num % den != 0) && ((num < 0) != (den < 0))) --fl;
  const int64_t rem2 = 2 * (num - fl * den);  // 2*rem in [0, 2*den)
  switch (q) {
    case Quant::Trunc: return fl;
    case Quant::RoundHalfUp: return rem2 >= den ? fl + 1 : fl;
    case Quant::RoundHalfEven:
      if (rem2 > den) return fl + 1;
      if (rem2 < den) return fl;
      return (fl % 2 == 0) ? fl : fl + 1;
  }
  return fl;
}

int64_t refFit(int64_t v, FixedFormat fmt, Overflow o) {
  if (v >= fmt.rawMin() && v <= fmt.rawMax()) return v;
  if (o == Overflow::Saturate) return v < fmt.rawMin() ? fmt.rawMin() : fmt.rawMax();
  const int64_t mod = int64_t{1} << fmt.width();
  int64_t w = ((v % mod) + mod) % mod;
  if (fmt.is_signed && w >= mod / 2) w -= mod;
  return w;
}

}  // namespace

TEST(FixedFormat, ParsesAndPrints) {
  EXPECT_EQ(FixedFormat::parse("uQ10.14"), FixedFormat::u(10, 14));
  EXPECT_EQ(FixedFormat::parse("sQ1.30"), FixedFormat::s(1, 30));
  EXPECT_EQ(FixedFormat::parse("uQ0.8"), FixedFormat::u(0, 8));
  EXPECT_EQ(FixedFormat::parse("uQ1.15").str(), "uQ1.15");
  EXPECT_EQ(FixedFormat::u(1, 15).rawMax(), 65535);
  EXPECT_EQ(FixedFormat::s(2, 2).rawMin(), -8);
  EXPECT_EQ(FixedFormat::s(2, 2).rawMax(), 7);
}

TEST(FixedFormat, RejectsMalformedText) {
  for (const char* bad : {"uQ10.x", "Q10.14", "uQ10", "u10.14", "xQ1.2", "uQ.3", "uQ1.", "sQ0.8",
                          "uQ40.40", "uQ0.0", "uQ-1.4", "uQ1.2.3", ""}) {
    EXPECT_THROW(FixedFormat::parse(bad), std::invalid_argument) << bad;
  }
  try {
    FixedFormat::parse("uQ10.x");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("uQ10.x"), std::string::npos) << e.what();
  }
}

TEST(Fixed, ConvertExhaustiveAllModes) {
  const auto fmts = smallFormats();
  long checked = 0;
  for (FixedFormat from : fmts)
    for (FixedFormat to : fmts)
      for (Quant q : {Quant::Trunc, Quant::RoundHalfUp, Quant::RoundHalfEven})
        for (Overflow o : {Overflow::Wrap, Overflow::Saturate})
          for (int64_t r = from.rawMin(); r <= from.rawMax(); ++r) {
            const Fixed x = Fixed::fromRaw(r, from);
            // Reference: value * 2^to.f = r * 2^(to.f - from.f), rounded.
            const int64_t num = scaled(r, from.frac_bits);  // value * 2^kD
            const int64_t q_ref = refRound(num, kD - to.frac_bits, q);
            const int64_t expect = refFit(q_ref, to, o);
            const Fixed y = x.convert(to, q, o);
            ASSERT_EQ(y.raw(), expect) << x.str() << " -> " << to.str() << " " << toString(q)
                                       << " " << toString(o);
            ASSERT_EQ(y.format(), to);
            ++checked;
          }
  EXPECT_GT(checked, 50000);
}

TEST(Fixed, OverflowErrorThrows) {
  const Fixed x = Fixed::fromRaw(7, FixedFormat::u(3, 0));
  EXPECT_THROW(x.convert(FixedFormat::u(2, 0), Quant::Trunc, Overflow::Error), std::overflow_error);
  EXPECT_EQ(x.convert(FixedFormat::u(3, 1), Quant::Trunc, Overflow::Error).raw(), 14);
  EXPECT_THROW(Fixed::fromRaw(8, FixedFormat::u(3, 0)), std::out_of_range);
}

TEST(Fixed, ArithmeticExhaustiveIsExact) {
  const auto fmts = smallFormats();
  for (FixedFormat fa : fmts)
    for (FixedFormat fb : fmts)
      for (int64_t ra = fa.rawMin(); ra <= fa.rawMax(); ++ra)
        for (int64_t rb = fb.rawMin(); rb <= fb.rawMax(); ++rb) {
          const Fixed a = Fixed::fromRaw(ra, fa), b = Fixed::fromRaw(rb, fb);
          const int64_t va = scaled(ra, fa.frac_bits), vb = scaled(rb, fb.frac_bits);
          const Fixed s = a + b, d = a - b, p = a * b;
          // Every result is exact: its value equals the rational result.
          ASSERT_EQ(scaled(s.raw(), s.format().frac_bits), va + vb) << a.str() << " + " << b.str();
          ASSERT_EQ(scaled(d.raw(), d.format().frac_bits), va - vb) << a.str() << " - " << b.str();
          ASSERT_EQ(p.raw() * (int64_t{1} << (2 * kD - p.format().frac_bits)), va * vb) << a.str() << " * " << b.str();
          // ...and fits the grown format (fromRaw would throw otherwise).
          ASSERT_TRUE(s.format().holds(s.raw()));
          ASSERT_TRUE(d.format().holds(d.raw()));
          ASSERT_TRUE(p.format().holds(p.raw()));
          ASSERT_TRUE(d.format().is_signed);
          ASSERT_EQ(compare(a, b), va < vb ? -1 : (va > vb ? 1 : 0));
        }
}

TEST(Fixed, GrownFormatsAreTight) {
  // The full-precision formats are the smallest that hold every result: the extremes reach
  // the top bit (no spare bits wasted).
  const FixedFormat u = FixedFormat::u(2, 2), s = FixedFormat::s(2, 2);
  const Fixed umax = Fixed::fromRaw(u.rawMax(), u), smin = Fixed::fromRaw(s.rawMin(), s);
  EXPECT_EQ((umax + umax).format(), FixedFormat::u(3, 2));
  EXPECT_GT((umax + umax).raw(), FixedFormat::u(2, 2).rawMax());
  EXPECT_EQ((smin * smin).format(), FixedFormat::s(4, 4));
  EXPECT_GT((smin * smin).raw(), FixedFormat::s(3, 4).rawMax());
  EXPECT_EQ((umax * smin).format(), FixedFormat::s(4, 4));
}

TEST(Fixed, WideResultThrows) {
  const Fixed a = Fixed::fromRaw(1, FixedFormat::u(10, 30));
  EXPECT_THROW(a * a, std::overflow_error);
}

TEST(Fixed, FromDoubleExactAndRounded) {
  const FixedFormat f = FixedFormat::u(10, 14);
  EXPECT_EQ(Fixed::fromDouble(1.0, f, Quant::Trunc, Overflow::Error).raw(), 1 << 14);
  // Ties: 2.5 LSB -> half-up 3, half-even 2, trunc 2; -2.5 LSB -> half-up -2, half-even -2, trunc -3.
  const FixedFormat g = FixedFormat::s(4, 0);
  EXPECT_EQ(Fixed::fromDouble(2.5, g, Quant::RoundHalfUp, Overflow::Error).raw(), 3);
  EXPECT_EQ(Fixed::fromDouble(2.5, g, Quant::RoundHalfEven, Overflow::Error).raw(), 2);
  EXPECT_EQ(Fixed::fromDouble(2.5, g, Quant::Trunc, Overflow::Error).raw(), 2);
  EXPECT_EQ(Fixed::fromDouble(-2.5, g, Quant::RoundHalfUp, Overflow::Error).raw(), -2);
  EXPECT_EQ(Fixed::fromDouble(-2.5, g, Quant::RoundHalfEven, Overflow::Error).raw(), -2);
  EXPECT_EQ(Fixed::fromDouble(-2.5, g, Quant::Trunc, Overflow::Error).raw(), -3);
  // The largest double below 0.5: a naive floor(x + 0.5) rounds it up; we must not.
  EXPECT_EQ(Fixed::fromDouble(std::nextafter(0.5, 0.0), g, Quant::RoundHalfUp, Overflow::Error).raw(), 0);
  EXPECT_EQ(Fixed::fromDouble(1e30, g, Quant::Trunc, Overflow::Saturate).raw(), 7);
  EXPECT_THROW(Fixed::fromDouble(1e30, g, Quant::Trunc, Overflow::Error), std::overflow_error);
  EXPECT_THROW(Fixed::fromDouble(NAN, g, Quant::Trunc, Overflow::Saturate), std::invalid_argument);
}

TEST(Fixed, FromDoubleMatchesConvertExhaustive) {
  // Every value of a 12-bit format, rounded to a 6-bit format from double and from Fixed.
  const FixedFormat from = FixedFormat::s(4, 8), to = FixedFormat::s(3, 3);
  for (Quant q : {Quant::Trunc, Quant::RoundHalfUp, Quant::RoundHalfEven})
    for (int64_t r = from.rawMin(); r <= from.rawMax(); ++r) {
      const Fixed x = Fixed::fromRaw(r, from);
      ASSERT_EQ(Fixed::fromDouble(x.toDouble(), to, q, Overflow::Saturate).raw(),
                x.convert(to, q, Overflow::Saturate).raw())
          << x.str();
    }
}
