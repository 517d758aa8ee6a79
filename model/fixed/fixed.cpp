#include "fixed/fixed.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace shd {

const char* toString(Quant q) {
  switch (q) {
    case Quant::Trunc: return "trunc";
    case Quant::RoundHalfUp: return "round-half-up";
    case Quant::RoundHalfEven: return "round-half-even";
  }
  return "?";
}

const char* toString(Overflow o) {
  switch (o) {
    case Overflow::Wrap: return "wrap";
    case Overflow::Saturate: return "saturate";
    case Overflow::Error: return "error";
  }
  return "?";
}

Quant parseQuant(std::string_view s) {
  for (Quant q : {Quant::Trunc, Quant::RoundHalfUp, Quant::RoundHalfEven})
    if (s == toString(q)) return q;
  throw std::invalid_argument(
      fmt::format("unknown rounding mode '{}' (expected trunc, round-half-up or round-half-even)", s));
}

Overflow parseOverflow(std::string_view s) {
  for (Overflow o : {Overflow::Wrap, Overflow::Saturate, Overflow::Error})
    if (s == toString(o)) return o;
  throw std::invalid_argument(
      fmt::format("unknown overflow mode '{}' (expected wrap, saturate or error)", s));
}

void FixedFormat::validate() const {
  if (int_bits < 0 || frac_bits < 0)
    throw std::invalid_argument(fmt::format("fixed-point format {}: negative bit count", str()));
  if (is_signed && int_bits < 1)
    throw std::invalid_argument(
        fmt::format("fixed-point format {}: a signed format needs its sign bit (m >= 1)", str()));
  if (width() < 1 || width() > kMaxWidth)
    throw std::invalid_argument(fmt::format(
        "fixed-point format {}: width {} outside 1..{}", str(), width(), kMaxWidth));
}

static bool parseCount(std::string_view s, int& out) {
  if (s.empty() || s.size() > 3) return false;
  int v = 0;
  for (char ch : s) {
    if (ch < '0' || ch > '9') return false;
    v = v * 10 + (ch - '0');
  }
  out = v;
  return true;
}

FixedFormat FixedFormat::parse(std::string_view text) {
  auto bad = [&](const char* why) {
    return std::invalid_argument(
        fmt::format("malformed fixed-point format '{}': {} (expected uQm.f or sQm.f, e.g. uQ10.14)",
                    text, why));
  };
  if (text.size() < 5) throw bad("too short");
  FixedFormat f;
  if (text[0] == 'u') f.is_signed = false;
  else if (text[0] == 's') f.is_signed = true;
  else throw bad("must start with 'u' or 's'");
  if (text[1] != 'Q') throw bad("second character must be 'Q'");
  const std::string_view body = text.substr(2);
  const size_t dot = body.find('.');
  if (dot == std::string_view::npos) throw bad("missing '.' between m and f");
  if (!parseCount(body.substr(0, dot), f.int_bits)) throw bad("m is not a whole number");
  if (!parseCount(body.substr(dot + 1), f.frac_bits)) throw bad("f is not a whole number");
  f.validate();
  return f;
}

std::string FixedFormat::str() const {
  return fmt::format("{}Q{}.{}", is_signed ? 's' : 'u', int_bits, frac_bits);
}

static __int128 floorShift(__int128 v, int k) {  // floor(v / 2^k), k >= 0
  return v >> k;  // arithmetic shift on a signed 128-bit value is floor division
}

// v * 2^k without shifting a negative value left (undefined before C++20).
static __int128 scaleUp(__int128 v, int k) { return v * (static_cast<__int128>(1) << k); }

__int128 requantize(__int128 raw, int from_frac, int to_frac, Quant q) {
  const int shift = from_frac - to_frac;
  if (shift <= 0) return scaleUp(raw, -shift);
  const __int128 quot = floorShift(raw, shift);
  const __int128 rem = raw - scaleUp(quot, shift);  // in [0, 2^shift)
  const __int128 half = static_cast<__int128>(1) << (shift - 1);
  switch (q) {
    case Quant::Trunc: return quot;
    case Quant::RoundHalfUp: return quot + (rem >= half ? 1 : 0);
    case Quant::RoundHalfEven:
      return quot + ((rem > half || (rem == half && (quot & 1) != 0)) ? 1 : 0);
  }
  return quot;
}

int64_t fitRaw(__int128 raw, FixedFormat fmt, Overflow o) {
  if (raw >= fmt.rawMin() && raw <= fmt.rawMax()) return static_cast<int64_t>(raw);
  switch (o) {
    case Overflow::Saturate: return raw < fmt.rawMin() ? fmt.rawMin() : fmt.rawMax();
    case Overflow::Wrap: {
      const int w = fmt.width();
      const unsigned __int128 mask = (static_cast<unsigned __int128>(1) << w) - 1;
      __int128 low = static_cast<__int128>(static_cast<unsigned __int128>(raw) & mask);
      if (fmt.is_signed && (low >> (w - 1)) != 0) low -= static_cast<__int128>(1) << w;
      return static_cast<int64_t>(low);
    }
    case Overflow::Error: break;
  }
  throw std::overflow_error(fmt::format("value does not fit fixed-point format {}", fmt.str()));
}

Fixed Fixed::fromRaw(int64_t raw, FixedFormat fmt) {
  if (!fmt.holds(raw))
    throw std::out_of_range(fmt::format("raw value {} outside format {}", raw, fmt.str()));
  return Fixed(raw, fmt);
}

Fixed Fixed::fromInt(int64_t v, FixedFormat fmt, Overflow o) {
  const __int128 raw = scaleUp(v, fmt.frac_bits);
  return Fixed(fitRaw(raw, fmt, o), fmt);
}

Fixed Fixed::fromDouble(double x, FixedFormat fmt, Quant q, Overflow o) {
  if (!std::isfinite(x))
    throw std::invalid_argument(fmt::format("cannot convert non-finite {} to {}", x, fmt.str()));
  const double y = std::ldexp(x, fmt.frac_bits);  // exact scaling by a power of two
  const double fl = std::floor(y);
  const double rem = y - fl;  // exact: y and fl share the exponent range, rem in [0, 1)
  // Values beyond 2^100 cannot be represented by any legal format: saturate or fail.
  if (std::fabs(fl) > 0x1p100) {
    if (o == Overflow::Saturate) return Fixed(y < 0 ? fmt.rawMin() : fmt.rawMax(), fmt);
    throw std::overflow_error(fmt::format("{} does not fit fixed-point format {}", x, fmt.str()));
  }
  // (through int64_t when it fits: the direct double -> __int128 conversion is a slow libgcc call)
  __int128 quot = std::fabs(fl) < 0x1p62 ? static_cast<__int128>(static_cast<int64_t>(fl)) : static_cast<__int128>(fl);
  switch (q) {
    case Quant::Trunc: break;
    case Quant::RoundHalfUp: quot += rem >= 0.5 ? 1 : 0; break;
    case Quant::RoundHalfEven: quot += (rem > 0.5 || (rem == 0.5 && (quot & 1) != 0)) ? 1 : 0; break;
  }
  try {
    return Fixed(fitRaw(quot, fmt, o), fmt);
  } catch (const std::overflow_error&) {
    throw std::overflow_error(fmt::format("{} does not fit fixed-point format {}", x, fmt.str()));
  }
}

double Fixed::toDouble() const { return std::ldexp(static_cast<double>(raw_), -fmt_.frac_bits); }

std::string Fixed::str() const {
  return fmt::format("{}({}) = {}", raw_, fmt_.str(), toDouble());
}

Fixed Fixed::convert(FixedFormat to, Quant q, Overflow o) const {
  const __int128 r = requantize(raw_, fmt_.frac_bits, to.frac_bits, q);
  try {
    return Fixed(fitRaw(r, to, o), to);
  } catch (const std::overflow_error&) {
    throw std::overflow_error(
        fmt::format("{} does not fit fixed-point format {}", str(), to.str()));
  }
}

namespace {

FixedFormat checked(FixedFormat r, const char* op, FixedFormat a, FixedFormat b) {
  if (r.width() > FixedFormat::kMaxWidth)
    throw std::overflow_error(fmt::format("{} {} {} needs {} bits ({}), more than {}", a.str(), op,
                                          b.str(), r.width(), r.str(), FixedFormat::kMaxWidth));
  return r;
}

// Integer bits an operand needs inside a result of the given signedness.
int intBitsAs(FixedFormat f, bool result_signed) {
  return f.int_bits + ((result_signed && !f.is_signed) ? 1 : 0);
}

FixedFormat sumFormat(FixedFormat a, FixedFormat b, bool result_signed) {
  return FixedFormat(result_signed,
                     std::max(intBitsAs(a, result_signed), intBitsAs(b, result_signed)) + 1,
                     std::max(a.frac_bits, b.frac_bits));
}

__int128 aligned(Fixed x, int frac) {
  return scaleUp(x.raw(), frac - x.format().frac_bits);
}

}  // namespace

Fixed operator+(Fixed a, Fixed b) {
  const FixedFormat r = checked(sumFormat(a.fmt_, b.fmt_, a.fmt_.is_signed || b.fmt_.is_signed),
                                "+", a.fmt_, b.fmt_);
  return Fixed(static_cast<int64_t>(aligned(a, r.frac_bits) + aligned(b, r.frac_bits)), r);
}

Fixed operator-(Fixed a, Fixed b) {
  const FixedFormat r = checked(sumFormat(a.fmt_, b.fmt_, true), "-", a.fmt_, b.fmt_);
  return Fixed(static_cast<int64_t>(aligned(a, r.frac_bits) - aligned(b, r.frac_bits)), r);
}

Fixed operator*(Fixed a, Fixed b) {
  const FixedFormat r =
      checked(FixedFormat(a.fmt_.is_signed || b.fmt_.is_signed, a.fmt_.int_bits + b.fmt_.int_bits,
                          a.fmt_.frac_bits + b.fmt_.frac_bits),
              "*", a.fmt_, b.fmt_);
  return Fixed(static_cast<int64_t>(static_cast<__int128>(a.raw_) * b.raw_), r);
}

Fixed Fixed::operator-() const {
  const FixedFormat r = checked(FixedFormat(true, intBitsAs(fmt_, true) + 1, fmt_.frac_bits),
                                "negate", fmt_, fmt_);
  return Fixed(-raw_, r);
}

int compare(Fixed a, Fixed b) {
  const int f = std::max(a.fmt_.frac_bits, b.fmt_.frac_bits);
  const __int128 x = aligned(a, f), y = aligned(b, f);
  return x < y ? -1 : (x > y ? 1 : 0);
}

}  // namespace shd
