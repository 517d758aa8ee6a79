// Integer-backed fixed-point numbers in the spirit of ac_fixed / sc_fixed.
//
// A format is spelt uQm.f or sQm.f: m integer bits (the sign bit included when signed),
// f fraction bits, width m+f. A value is its raw two's-complement integer and its format;
// nothing is routed through double. Arithmetic operators keep full precision (the result
// format grows so that no bit is lost); rounding and overflow happen only in convert(), with
// a named mode, exactly where the RTL drops or saturates bits.
//
// Widths are limited to 62 bits so that every full-precision product of two legal operands
// can be formed exactly in a 128-bit intermediate and every legal value fits in int64_t.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace shd {

// Quantisation when fraction bits are dropped.
//   Trunc          floor: drop the bits (what a hardware bit-select of a two's-complement
//                  value does); rounds toward -infinity.
//   RoundHalfUp    nearest, ties toward +infinity: add half an LSB, then drop.
//   RoundHalfEven  nearest, ties to the even neighbour (convergent rounding).
enum class Quant { Trunc, RoundHalfUp, RoundHalfEven };

// Overflow when the value does not fit the target format.
//   Wrap      keep the low bits (two's complement), as a narrower hardware bus does.
//   Saturate  clamp to the nearest representable value.
//   Error     throw std::overflow_error: for widths the design claims are sufficient.
enum class Overflow { Wrap, Saturate, Error };

const char* toString(Quant q);
const char* toString(Overflow o);
Quant parseQuant(std::string_view s);        // "trunc", "round-half-up", "round-half-even"
Overflow parseOverflow(std::string_view s);  // "wrap", "saturate", "error"

struct FixedFormat {
  static constexpr int kMaxWidth = 62;

  bool is_signed = false;
  int int_bits = 1;   // m, sign bit included when signed
  int frac_bits = 0;  // f

  constexpr FixedFormat() = default;
  constexpr FixedFormat(bool s, int m, int f) : is_signed(s), int_bits(m), frac_bits(f) {}
  static constexpr FixedFormat u(int m, int f) { return {false, m, f}; }
  static constexpr FixedFormat s(int m, int f) { return {true, m, f}; }

  constexpr int width() const { return int_bits + frac_bits; }
  constexpr int64_t rawMin() const {
    return is_signed ? -(int64_t{1} << (width() - 1)) : 0;
  }
  constexpr int64_t rawMax() const {
    return is_signed ? (int64_t{1} << (width() - 1)) - 1 : (int64_t{1} << width()) - 1;
  }
  constexpr bool holds(int64_t raw) const { return raw >= rawMin() && raw <= rawMax(); }

  // Throws std::invalid_argument unless 1 <= width <= kMaxWidth, m >= 0, f >= 0 and a signed
  // format has its sign bit (m >= 1).
  void validate() const;
  // Parses "uQ10.14" / "sQ1.30"; throws std::invalid_argument naming the text on error.
  static FixedFormat parse(std::string_view text);
  std::string str() const;

  friend constexpr bool operator==(FixedFormat a, FixedFormat b) {
    return a.is_signed == b.is_signed && a.int_bits == b.int_bits && a.frac_bits == b.frac_bits;
  }
  friend constexpr bool operator!=(FixedFormat a, FixedFormat b) { return !(a == b); }
};

// Quantise raw * 2^-from_frac to to_frac fraction bits (no overflow handling): the shared
// primitive of every conversion, also used by the unit models on raw integers.
__int128 requantize(__int128 raw, int from_frac, int to_frac, Quant q);
// Fit a quantised raw value into fmt according to the overflow mode.
int64_t fitRaw(__int128 raw, FixedFormat fmt, Overflow o);

class Fixed {
 public:
  constexpr Fixed() = default;

  // raw must be representable in fmt (std::out_of_range otherwise).
  static Fixed fromRaw(int64_t raw, FixedFormat fmt);
  static Fixed fromInt(int64_t v, FixedFormat fmt, Overflow o = Overflow::Error);
  // Exact: x * 2^f is formed without error (ldexp), then quantised and fitted.
  // Non-finite x throws std::invalid_argument.
  static Fixed fromDouble(double x, FixedFormat fmt, Quant q, Overflow o);

  constexpr int64_t raw() const { return raw_; }
  constexpr FixedFormat format() const { return fmt_; }
  double toDouble() const;  // for reports only; exact when width <= 53
  std::string str() const;  // "0x..(uQ1.15) = 0.5"

  Fixed convert(FixedFormat to, Quant q, Overflow o) const;

  // Full precision. Formats grow as in ac_fixed:
  //   a + b, a - b : f = max(fa, fb); m = max(ma', mb') + 1 where an unsigned operand counts
  //                  one extra integer bit when the result is signed; a - b is always signed.
  //   a * b        : f = fa + fb; m = ma + mb.
  // A result wider than kMaxWidth throws std::overflow_error naming both formats.
  friend Fixed operator+(Fixed a, Fixed b);
  friend Fixed operator-(Fixed a, Fixed b);
  friend Fixed operator*(Fixed a, Fixed b);
  Fixed operator-() const;

  // Exact value comparison (formats may differ).
  friend int compare(Fixed a, Fixed b);
  friend bool operator==(Fixed a, Fixed b) { return compare(a, b) == 0; }
  friend bool operator!=(Fixed a, Fixed b) { return compare(a, b) != 0; }
  friend bool operator<(Fixed a, Fixed b) { return compare(a, b) < 0; }
  friend bool operator<=(Fixed a, Fixed b) { return compare(a, b) <= 0; }
  friend bool operator>(Fixed a, Fixed b) { return compare(a, b) > 0; }
  friend bool operator>=(Fixed a, Fixed b) { return compare(a, b) >= 0; }

 private:
  constexpr Fixed(int64_t raw, FixedFormat fmt) : raw_(raw), fmt_(fmt) {}
  int64_t raw_ = 0;
  FixedFormat fmt_{};
};

}  // namespace shd
