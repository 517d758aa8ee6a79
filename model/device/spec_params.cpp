#include "device/spec_params.h"

#include <algorithm>

#include <fmt/format.h>

#include "config/params_json.h"

namespace shd {

namespace {

constexpr ParamMember<SpecUnitParams> kMembers[] = {
    {"Degree", &SpecUnitParams::Degree},
    {"CosFracBits", &SpecUnitParams::CosFracBits},
    {"ShinBits", &SpecUnitParams::ShinBits},
    {"CoefIntBits", &SpecUnitParams::CoefIntBits},
    {"CoefFracBits", &SpecUnitParams::CoefFracBits},
    {"DiffFracBits", &SpecUnitParams::DiffFracBits},
    {"HornerFracBits", &SpecUnitParams::HornerFracBits},
    {"SpecFracBits", &SpecUnitParams::SpecFracBits},
    {"LightBits", &SpecUnitParams::LightBits},
    {"PipeStages", &SpecUnitParams::PipeStages},
    {"Kind", &SpecUnitParams::Kind, true},
    {"TableBits", &SpecUnitParams::TableBits, true},
    {"Segments", &SpecUnitParams::Segments, true},
};

// Bits of a count up to n - 1, at least 1 (Verilog's $clog2 for n >= 2).
int clog2(int n) {
  int bits = 1;
  while ((1 << bits) < n) ++bits;
  return bits;
}

void require(bool ok, const char* param, int value, const std::string& rule) {
  if (!ok)
    throw std::invalid_argument(fmt::format("parameter {} = {}: {}", param, value, rule));
}

// Width of a full-precision product or sum the model forms in int64_t.
void requireModelWidth(int width, const std::string& what) {
  if (width > FixedFormat::kMaxWidth)
    throw std::invalid_argument(fmt::format(
        "{} needs {} bits, more than the {} the model holds exactly; narrow the widths", what,
        width, FixedFormat::kMaxWidth));
}

// The checks of one kind's own datapath (the common ones are in validate()).
void validateTable(const SpecUnitParams& p) {
  require(p.TableBits >= 1 && p.TableBits <= p.CosFracBits, "TableBits", p.TableBits,
          fmt::format("must be in 1..CosFracBits = {}", p.CosFracBits));
  require(p.ShinBits + p.TableBits <= 24, "TableBits", p.TableBits,
          fmt::format("ShinBits + TableBits = {} exceeds the 24 address bits a PROM file may have", p.ShinBits + p.TableBits));
  require(p.PipeStages >= 0 && p.PipeStages <= 1, "PipeStages", p.PipeStages, "must be 0 or 1 for the table");
}

void validateSchlick(const SpecUnitParams& p) {
  require(p.PipeStages >= 0 && p.PipeStages <= p.SpecFracBits + 1, "PipeStages", p.PipeStages,
          fmt::format("must be in 0..SpecFracBits+1 = {} (one register rank per divider step at most)",
                      p.SpecFracBits + 1));
  const int kw = p.CoefIntBits + p.CoefFracBits;
  requireModelWidth(kw + p.CosFracBits + 1, "den = m*(1-c) + 1");
  requireModelWidth(p.CosFracBits + 1 + p.CoefFracBits + p.SpecFracBits, "the dividend c * 2^(Cf+Wf)");
}

void validateExpLog(const SpecUnitParams& p) {
  const int tmax = std::min(p.CosFracBits, p.SpecFracBits + 3);
  require(p.TableBits >= 1 && p.TableBits <= tmax, "TableBits", p.TableBits,
          fmt::format("must be in 1..min(CosFracBits, SpecFracBits+3) = {} for explog", tmax));
  require(p.PipeStages >= 1 && p.PipeStages <= 3, "PipeStages", p.PipeStages,
          "must be in 1..3 for explog (the exp table's read is one register rank)");
  const ExpLogWidths w = p.expLogWidths();
  require(w.GF <= 56, "CoefIntBits", p.CoefIntBits,
          fmt::format("makes the log table's fraction bits {} exceed 56 (its entries are computed to 60 bits)", w.GF));
  requireModelWidth(p.CoefIntBits + p.CoefFracBits + w.LI + w.LF, "y = n * L");
  requireModelWidth(p.CosFracBits + 1 + w.gBits(), "P = D * G");
}

void validatePiecewise(const SpecUnitParams& p) {
  require(p.Degree >= 1 && p.Degree <= 3, "Degree", p.Degree, "must be in 1..3 for piecewise");
  require(p.Segments == 1 || p.Segments == 2 || p.Segments == 4, "Segments", p.Segments,
          "must be 1, 2 or 4 for piecewise");
  require(p.PipeStages >= 1 && p.PipeStages <= p.Degree + 1, "PipeStages", p.PipeStages,
          fmt::format("must be in 1..Degree+1 = {} for piecewise (the segment ROM's read, then one rank per "
                      "Horner step at most)",
                      p.Degree + 1));
  require(p.CoefFracBits >= p.SpecFracBits, "CoefFracBits", p.CoefFracBits,
          fmt::format("must be at least SpecFracBits = {} (f is rounded from the coefficients' fraction bits)",
                      p.SpecFracBits));
  require(p.segWordBits() <= 128, "CoefIntBits", p.CoefIntBits,
          fmt::format("makes the segment ROM word {} bits, more than 128", p.segWordBits()));
  // The Horner accumulator (Ci + Cf + 3 bits, rtl/shd_spec_piecewise.v) times u (Wc + 1 bits).
  requireModelWidth(p.CoefIntBits + p.CoefFracBits + 3 + p.CosFracBits + 1, "the Horner product acc * u");
}

void validatePoly(const SpecUnitParams& p) {
  require(p.Degree == 2 || p.Degree == 3, "Degree", p.Degree, "must be 2 or 3");
  require(p.DiffFracBits >= 2 && p.DiffFracBits <= 2 * p.CosFracBits, "DiffFracBits", p.DiffFracBits,
          fmt::format("must be in 2..2*CosFracBits = {} (c^2 - c is exact at 2*CosFracBits "
                      "fraction bits)",
                      2 * p.CosFracBits));
  require(p.PipeStages >= 0 && p.PipeStages <= 3, "PipeStages", p.PipeStages, "must be in 0..3");
  require(p.SpecFracBits >= p.CosFracBits, "SpecFracBits", p.SpecFracBits,
          fmt::format("must be at least CosFracBits = {} (c enters Sm2 unrounded)", p.CosFracBits));
  const int prod_frac = p.CoefFracBits + p.DiffFracBits;
  if (p.Degree == 3) {
    require(p.HornerFracBits >= 0 && p.HornerFracBits <= p.CoefFracBits + p.CosFracBits, "HornerFracBits",
            p.HornerFracBits,
            fmt::format("must be in 0..CoefFracBits+CosFracBits = {} (u*c + v is exact there)",
                        p.CoefFracBits + p.CosFracBits));
  }
  const int mul2_frac = p.Degree == 2 ? prod_frac : p.HornerFracBits + p.DiffFracBits;
  require(p.SpecFracBits <= mul2_frac, "SpecFracBits", p.SpecFracBits,
          fmt::format("must not exceed the MUL2 product's {} fraction bits", mul2_frac));
  // Every full-precision intermediate the model forms (formats as in Fixed's operators).
  requireModelWidth(2 + 2 * p.CosFracBits, "MUL1 c*c");
  if (p.Degree == 2) {
    requireModelWidth(p.CoefIntBits + 1 + prod_frac, "MUL2 a*(c^2-c)");
  } else {
    requireModelWidth(p.CoefIntBits + 2 + p.CoefFracBits + p.CosFracBits, "Horner u*c + v");
    requireModelWidth(p.CoefIntBits + 2 + p.HornerFracBits + p.DiffFracBits, "MUL2 (c^2-c)*g");
  }
}

}  // namespace

const std::vector<SpecKindInfo>& specKinds() {
  static const std::vector<SpecKindInfo> kinds = {
      {SpecKind::Poly, "poly", "the paper's device: a fitted polynomial, coefficients from the PROM"},
      {SpecKind::Table, "table", "c^n read from a table over shininess and cosine codes"},
      {SpecKind::Schlick, "schlick", "Schlick's rational c / (n - n c + c), with a divider"},
      {SpecKind::ExpLog, "explog", "c^n = 2^(n log2 c) by logarithm and exponent tables, interpolated"},
      {SpecKind::Piecewise, "piecewise", "a minimax polynomial per cosine segment, 1, 2 or 4 segments per n"},
  };
  return kinds;
}

const SpecKindInfo& specKindInfo(SpecKind k) {
  for (const SpecKindInfo& i : specKinds())
    if (i.kind == k) return i;
  throw std::invalid_argument(fmt::format("unknown specular unit kind {}", static_cast<int>(k)));
}

int SpecUnitParams::promWordBits() const {
  switch (kind()) {
    case SpecKind::Table: return SpecFracBits + 1;
    case SpecKind::Schlick:
    case SpecKind::ExpLog: return coefFormat().width();
    case SpecKind::Piecewise: return Segments * (CosFracBits + 1);
    case SpecKind::Poly: break;
  }
  return Degree == 2 ? coefFormat().width() : 2 * coefFormat().width() + CosFracBits + 1;
}

int SpecUnitParams::segAddrBits() const { return ShinBits + (Segments >= 4 ? 2 : Segments >= 2 ? 1 : 0); }

int SpecUnitParams::segScaleBits() const { return clog2(CosFracBits + 1); }

int SpecUnitParams::segWordBits() const { return segScaleBits() + (Degree + 1) * coefFormat().width(); }

ExpLogWidths SpecUnitParams::expLogWidths() const {
  const int wf = SpecFracBits;
  return {wf + 6 + std::max(0, CoefIntBits - CosFracBits - 4), wf + CoefIntBits + 3, wf + 4, wf + 3,
          clog2(CosFracBits + 1)};
}

int64_t SpecUnitParams::fixedRomBits() const {
  if (kind() != SpecKind::ExpLog) return 0;
  const ExpLogWidths w = expLogWidths();
  return (int64_t{1} << TableBits) *
         (w.gStepBits(TableBits) + w.gBits() + w.eStepBits(TableBits) + w.eBits());
}

void SpecUnitParams::validate() const {
  if (Kind < 0 || Kind >= static_cast<int>(specKinds().size())) {
    std::string names;
    for (const SpecKindInfo& k : specKinds())
      names += fmt::format("{}{} {}", names.empty() ? "" : ", ", static_cast<int>(k.kind), k.name);
    require(false, "Kind", Kind, fmt::format("must be in 0..{} ({})", specKinds().size() - 1, names));
  }
  require(CosFracBits >= 2 && CosFracBits <= 24, "CosFracBits", CosFracBits, "must be in 2..24");
  require(ShinBits >= 1 && ShinBits <= 16, "ShinBits", ShinBits, "must be in 1..16");
  require(CoefIntBits >= 1 && CoefIntBits <= 32, "CoefIntBits", CoefIntBits, "must be in 1..32");
  require(CoefFracBits >= 0 && CoefFracBits <= 40, "CoefFracBits", CoefFracBits, "must be in 0..40");
  require(LightBits >= 1 && LightBits <= 16, "LightBits", LightBits, "must be in 1..16");
  require(SpecFracBits >= 1 && SpecFracBits <= 30, "SpecFracBits", SpecFracBits,
          "must be in 1..30 (spec_o is at most 31 bits)");
  switch (kind()) {
    case SpecKind::Poly: validatePoly(*this); break;
    case SpecKind::Table: validateTable(*this); break;
    case SpecKind::Schlick: validateSchlick(*this); break;
    case SpecKind::ExpLog: validateExpLog(*this); break;
    case SpecKind::Piecewise: validatePiecewise(*this); break;
  }
  requireModelWidth(LightBits + 1 + SpecFracBits, "MUL3..MUL5 f*L");
  if (promWordBits() > 128)
    throw std::invalid_argument(
        fmt::format("PROM word of {} bits exceeds 128; narrow the coefficient", promWordBits()));
}

SpecUnitParams SpecUnitParams::fromJson(const nlohmann::json& rtl, const std::string& where) {
  return paramsFromJson(rtl, kMembers, true, where);
}

nlohmann::json SpecUnitParams::toJson() const { return paramsToJson(*this, kMembers); }

}  // namespace shd
