// libFuzzer target: the unit configuration reader (model/config/registry.h specConfig and
// spanConfig on a JSON file). Input: the file's bytes, read as a specular-unit and as a
// span-unit configuration. Clean rejection: std::invalid_argument (documented for both).
// Properties of an accepted configuration:
//   - its "rtl" parameters validate, and survive toJson -> fromJson unchanged;
//   - span: SpanUnitModel takes them;
//   - spec: SpecUnitModel takes them with any PROM content (all-zero and all-ones words), and
//     for every shininess code tried and the corner cos codes (0, 1 LSB, 1/2, 1.0 - 1 LSB, 1.0,
//     and the largest code of the port, which saturates to 1.0) evaluate() and the readable
//     trace() agree bit for bit, without an overflow: the widths validate() accepts hold every
//     intermediate, whatever the coefficients (rtl/shd_spec_unit.v proves the ranges);
//   - its "prom" section is either a request the PROM builder takes or a std::invalid_argument
//     (PromRequest::fromContent; the reader leaves those values to it).
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "config/registry.h"
#include "device/prom.h"
#include "device/spec_unit.h"
#include "fuzz_util.h"
#include "raster/span_unit.h"

namespace {

using shd::fuzz::finding;

void checkSpecDatapath(const shd::SpecUnitParams& p) {
  const int bits = p.promWordBits();
  // The largest word: all ones, but for the table, whose words are f <= 1.0, the word 1.0.
  const shd::PromWord ones = p.kind() == shd::SpecKind::Table ? shd::PromWord{1} << p.SpecFracBits
                             : bits >= 128                    ? ~shd::PromWord{0}
                                                              : (shd::PromWord{1} << bits) - 1;
  const uint32_t one = static_cast<uint32_t>(p.cosOne());
  const uint32_t cos_codes[] = {0, 1, one / 2, one - 1, one, 2 * one - 1};
  const uint32_t light = static_cast<uint32_t>(p.lightMax());
  const uint32_t last_shin = static_cast<uint32_t>(p.shinCodes() - 1);
  // The piecewise kind's segment ROM: zero, or every coefficient bit set with the scale 0 (a
  // larger one could carry u past 1.0, which the model refuses).
  const int seg_bits = p.kind() == shd::SpecKind::Piecewise ? p.segWordBits() : 1;
  const shd::PromWord seg_ones =
      (seg_bits >= 128 ? ~shd::PromWord{0} : (shd::PromWord{1} << seg_bits) - 1) >> p.segScaleBits() << p.segScaleBits();
  for (shd::PromWord word : {shd::PromWord{0}, ones}) {
    const shd::SpecUnitModel unit(p, std::vector<shd::PromWord>(static_cast<size_t>(p.promDepth()), word),
                                  std::vector<shd::PromWord>(static_cast<size_t>(p.segDepth()), word == 0 ? 0 : seg_ones));
    for (uint32_t shin : {0u, last_shin})
      for (uint32_t cos : cos_codes) {
        const shd::SpecOut out = unit.evaluate(shin, cos, {light, light, 0});
        const shd::SpecTrace t = unit.trace(shin, cos);
        if (static_cast<int64_t>(out.spec) != t.f.raw())
          finding(fmt::format("spec config {}: evaluate {} != trace {} at shin {} cos {} (PROM word {})",
                              p.toJson().dump(), out.spec, t.f.raw(), shin, cos, word == 0 ? "0" : "all ones"));
      }
  }
}

void checkSpec(const std::string& path) {
  shd::SpecUnitConfig c;
  try {
    c = shd::specConfig(path);
  } catch (const std::invalid_argument& e) {
    shd::fuzz::rejected(e);
    return;
  }
  c.rtl.validate();  // throws: the reader accepted parameters that do not validate
  const nlohmann::json j = c.rtl.toJson();
  if (shd::SpecUnitParams::fromJson(j, "round trip").toJson() != j)
    finding("spec rtl parameters change through toJson -> fromJson: " + j.dump());
  checkSpecDatapath(c.rtl);
  try {
    shd::PromRequest::fromContent(c.prom);
  } catch (const std::invalid_argument&) {
  }
}

void checkSpan(const std::string& path) {
  shd::SpanUnitConfig c;
  try {
    c = shd::spanConfig(path);
  } catch (const std::invalid_argument& e) {
    shd::fuzz::rejected(e);
    return;
  }
  const nlohmann::json j = c.rtl.toJson();
  if (shd::SpanParams::fromJson(j, "round trip").toJson() != j)
    finding("span rtl parameters change through toJson -> fromJson: " + j.dump());
  const shd::SpanUnitModel unit(c.rtl);  // validates them again
  if (!unit.idle()) finding("a span unit after reset is not idle");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = shd::fuzz::writeInput("config.json", data, size);
  checkSpec(path);
  checkSpan(path);
  return 0;
}
