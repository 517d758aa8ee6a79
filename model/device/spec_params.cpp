#include "device/spec_params.h"

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
};

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

}  // namespace

void SpecUnitParams::validate() const {
  require(Degree == 2 || Degree == 3, "Degree", Degree, "must be 2 or 3");
  require(CosFracBits >= 2 && CosFracBits <= 24, "CosFracBits", CosFracBits, "must be in 2..24");
  require(ShinBits >= 1 && ShinBits <= 16, "ShinBits", ShinBits, "must be in 1..16");
  require(CoefIntBits >= 1 && CoefIntBits <= 32, "CoefIntBits", CoefIntBits, "must be in 1..32");
  require(CoefFracBits >= 0 && CoefFracBits <= 40, "CoefFracBits", CoefFracBits, "must be in 0..40");
  require(DiffFracBits >= 2 && DiffFracBits <= 2 * CosFracBits, "DiffFracBits", DiffFracBits,
          fmt::format("must be in 2..2*CosFracBits = {} (c^2 - c is exact at 2*CosFracBits "
                      "fraction bits)",
                      2 * CosFracBits));
  require(LightBits >= 1 && LightBits <= 16, "LightBits", LightBits, "must be in 1..16");
  require(PipeStages >= 0 && PipeStages <= 3, "PipeStages", PipeStages, "must be in 0..3");
  const int prod_frac = CoefFracBits + DiffFracBits;
  if (Degree == 3) {
    require(HornerFracBits >= 0 && HornerFracBits <= CoefFracBits + CosFracBits, "HornerFracBits",
            HornerFracBits,
            fmt::format("must be in 0..CoefFracBits+CosFracBits = {} (u*c + v is exact there)",
                        CoefFracBits + CosFracBits));
  }
  const int mul2_frac = Degree == 2 ? prod_frac : HornerFracBits + DiffFracBits;
  require(SpecFracBits >= CosFracBits && SpecFracBits <= 30, "SpecFracBits", SpecFracBits,
          fmt::format("must be in CosFracBits = {} .. 30 (c enters Sm2 unrounded; spec_o is at "
                      "most 31 bits)",
                      CosFracBits));
  require(SpecFracBits <= mul2_frac, "SpecFracBits", SpecFracBits,
          fmt::format("must not exceed the MUL2 product's {} fraction bits", mul2_frac));
  // Every full-precision intermediate the model forms (formats as in Fixed's operators).
  requireModelWidth(2 + 2 * CosFracBits, "MUL1 c*c");
  if (Degree == 2) {
    requireModelWidth(CoefIntBits + 1 + prod_frac, "MUL2 a*(c^2-c)");
  } else {
    requireModelWidth(CoefIntBits + 2 + CoefFracBits + CosFracBits, "Horner u*c + v");
    requireModelWidth(CoefIntBits + 2 + HornerFracBits + DiffFracBits, "MUL2 (c^2-c)*g");
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
