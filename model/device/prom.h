// The coefficient PROM of the specular unit: which shininess values it holds (the address
// map), the fitted real coefficients, and their codes in the unit's coefficient format.
//
// Address map: entry i of the n list sits at address i (the table kind: its row of 2^TableBits
// words starts at i << TableBits). A range "lo:hi[:step]" lists
// lo, lo+step, ... up to hi; an explicit list "8,32,200" keeps the user's order. Addresses from
// the number of entries up to 2^ShinBits - 1 are unused and hold the all-zero word (degree 2:
// a = 0, f = c; degree 3: u = v = 0, no cut, f = c; schlick: m = 0, f = c; table: f = 0;
// explog: n = 0, f = 1 above c = 0; piecewise: every B = 0 and zero coefficients, f = 0).
// Contents per kind: poly, the fitted coefficients; schlick, m = n - 1; explog, n; table, the
// values of c^n per cosine bucket (prom.cpp fillTableEntry); piecewise, the first codes of the
// segments in the PROM and their scales and coefficients in the segment ROM, address
// {i, s} (fitPiecewise and quantisePiecewise of approx/piecewise.h).
// Rounding of the coefficients: round-half-even to the coefficient format (the table is made
// once, offline; half-even has no bias). A coefficient that does not fit the format is an
// error naming the fit, n and the format. The degree 3 cut-off code is ceil(cut * 2^Wc), so the
// device zeroes exactly the cos codes below the real cut.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "approx/fit.h"
#include "device/spec_params.h"
#include "device/spec_unit.h"

namespace shd {

struct NSpec {
  std::string text;  // as given
  bool is_list = false;
  std::vector<double> values;

  // Parses "lo:hi[:step]" (is_list = false) or "a,b,c" (is_list = true). Every n must lie in
  // [1, 1000]; std::invalid_argument naming the text otherwise.
  static NSpec parse(std::string_view text, bool is_list);
};

struct PromRequest {
  FitKind fit = FitKind::Inflection;
  double level = 0.5;
  NSpec n = NSpec::parse("1:1000", false);
  Quant coef_round = Quant::RoundHalfEven;

  // From a configuration's "prom" section.
  static PromRequest fromContent(const PromContent& c);
  std::string describe() const;  // "fit=inflection degree=2 n=1:1000 ..."
};

struct PromEntry {
  uint32_t address = 0;
  double n = 0;
  Approx approx;                // real coefficients
  SpecCoef code;                // raw codes stored in the word
  double u_real = 0, v_real = 0, cut_real = 0;  // the stored quantities before rounding (not the table's)
};

struct PromTable {
  SpecUnitParams unit;
  PromRequest request;
  std::vector<PromEntry> entries;  // address order
  std::vector<PromWord> words;     // unit.promDepth() words
  std::vector<PromWord> seg_words; // unit.segDepth() words: the piecewise kind's segment ROM

  // Index of the entry for shininess n, or -1.
  int addressOf(double n) const;
};

// std::invalid_argument unless the fit applies to the unit's kind: exact for the table, schlick
// and explog kinds, minimax for the piecewise kind, any other for the poly kind.
void checkFitForKind(FitKind fit, const SpecUnitParams& unit);

// Smallest ShinBits whose PROM holds `count` codes (at least 1).
int addressBitsFor(size_t count);

// Fits every n and quantises; std::invalid_argument if the entries do not fit 2^ShinBits
// addresses or a coefficient does not fit the format.
PromTable buildPromTable(const PromRequest& req, const SpecUnitParams& unit);

}  // namespace shd
