#include "render/phong_widths.h"

#include <algorithm>
#include <climits>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace shd {

namespace {

struct Member {
  const char* name;
  int PhongWidths::*field;
};

// In the datapath's order.
constexpr Member kMembers[] = {
    {"NormalFracBits", &PhongWidths::NormalFracBits},
    {"UnitFracBits", &PhongWidths::UnitFracBits},
    {"RsqrtSeedBits", &PhongWidths::RsqrtSeedBits},
    {"RsqrtSeedFracBits", &PhongWidths::RsqrtSeedFracBits},
    {"NewtonSteps", &PhongWidths::NewtonSteps},
    {"NewtonFracBits", &PhongWidths::NewtonFracBits},
    {"CosFracBits", &PhongWidths::CosFracBits},
    {"LobeCosBits", &PhongWidths::LobeCosBits},
    {"LobeCodeBits", &PhongWidths::LobeCodeBits},
    {"LobeIntBits", &PhongWidths::LobeIntBits},
    {"ColourFracBits", &PhongWidths::ColourFracBits},
    {"FactorIntBits", &PhongWidths::FactorIntBits},
};

const Member* findMember(const std::string& name) {
  for (const Member& m : kMembers)
    if (name == m.name) return &m;
  return nullptr;
}

std::string knownNames() {
  std::string s;
  for (const Member& m : kMembers) s += std::string(s.empty() ? "" : " ") + m.name;
  return s;
}

// A width within [lo, hi], else the error naming it and why the range is what it is.
void requireRange(const char* name, int value, int lo, int hi, const std::string& why) {
  if (value < lo || value > hi)
    throw std::invalid_argument(fmt::format("{} = {}: must be in {}..{} ({})", name, value, lo, hi, why));
}

// A derivation `lhs <= rhs` between widths, else the error naming the first width it involves.
void requireAtMost(const char* name, int value, const std::string& lhs_text, int lhs, const std::string& rhs_text,
                   int rhs, const std::string& why) {
  if (lhs <= rhs) return;
  const std::string limit = rhs_text == std::to_string(rhs) ? rhs_text : fmt::format("{} = {}", rhs_text, rhs);
  throw std::invalid_argument(fmt::format("{} = {}: {} = {} exceeds {}: {}", name, value, lhs_text, lhs, limit, why));
}

}  // namespace

void PhongWidths::validate() const {
  // Each width's own range: what its format and the model's containers can hold.
  requireRange("NormalFracBits", NormalFracBits, 1, 30,
               "the span unit carries the normal as attributes of AttrBits 32, which hold at most AttrBits - 2 "
               "fraction bits (RasterConfig), and |N|^2 at twice them fits 64 bits");
  requireRange("UnitFracBits", UnitFracBits, 1, 60, "L, H, V codes up to 2^UnitFracBits are held in 64 bits");
  requireRange("RsqrtSeedBits", RsqrtSeedBits, 0, 20, "the model builds seed tables of at most 2^20 entries");
  requireRange("RsqrtSeedFracBits", RsqrtSeedFracBits, 1, 30,
               "at 0 the seed's rounding can reach m r0^2 >= 3, where Newton's step turns negative; the model's "
               "seed words are 32 bits");
  requireRange("NewtonSteps", NewtonSteps, 0, 4, "0 uses the seed alone");
  requireRange("NewtonFracBits", NewtonFracBits, 1, 62, "m, 62 bits, is truncated to NewtonFracBits");
  requireRange("CosFracBits", CosFracBits, 2, 60,
               "R.V = 2 (N.L)(N.V) - L.V rounds by 2^(CosFracBits - 2); a cosine up to 2^(CosFracBits + 1) is held "
               "in 64 bits");
  requireRange("LobeCosBits", LobeCosBits, 1, 20, "the model builds lobe tables of at most 2^20 + 2 entries");
  requireRange("LobeCodeBits", LobeCodeBits, 0, 31, "the model's lobe words are 32 bits");
  requireRange("LobeIntBits", LobeIntBits, 1, 32, "f = 1, the peak of the phong, blinn and pow lobes, needs one");
  requireRange("ColourFracBits", ColourFracBits, 1, 38, "the output rounding adds 2^(ColourFracBits - 1)");
  requireRange("FactorIntBits", FactorIntBits, 8, 38, "a factor of full scale, 255 LSB, needs 8 integer bits");
  // The derivations between widths.
  requireAtMost("LobeCosBits", LobeCosBits, "LobeCosBits", LobeCosBits, "CosFracBits", CosFracBits,
                "the lobe table is read at the cosine's top LobeCosBits fraction bits");
  requireAtMost("LobeCodeBits", LobeCodeBits, "LobeCodeBits + LobeIntBits", LobeCodeBits + LobeIntBits, "32", 32,
                "the lobe word f_code must fit the model's 32-bit table entries");
  requireAtMost("CosFracBits", CosFracBits, "CosFracBits", CosFracBits, "UnitFracBits + NewtonFracBits",
                UnitFracBits + NewtonFracBits,
                "the cosine N.u r is rounded by a shift right of 31 + UnitFracBits + NewtonFracBits - CosFracBits - "
                "shift bits, which must be positive at every |N|^2 > 0 (shift up to 30)");
  requireAtMost("CosFracBits", CosFracBits, "32 + UnitFracBits + NewtonFracBits - CosFracBits",
                32 + UnitFracBits + NewtonFracBits - CosFracBits, "126", 126,
                "the cosine's rounding shift (shift = -1 for |N|^2 >= 2^(62 - 2 NormalFracBits)) must stay inside the "
                "128-bit product N.u r");
  requireAtMost("NormalFracBits", NormalFracBits, "NormalFracBits + UnitFracBits + NewtonFracBits + 4",
                NormalFracBits + UnitFracBits + NewtonFracBits + 4, "127", 127,
                "the product N.u r (|N.u| < 2^(NormalFracBits + UnitFracBits + 2), r < 2^(NewtonFracBits + 2)) must "
                "fit 128 bits with its sign");
  if (NewtonSteps > 0) {
    const int r_frac = std::max(RsqrtSeedFracBits, NewtonFracBits);
    requireAtMost("NewtonFracBits", NewtonFracBits, "NewtonFracBits + 2 max(RsqrtSeedFracBits, NewtonFracBits) + 2",
                  NewtonFracBits + 2 * r_frac + 2, "128", 128,
                  "Newton's product m r^2 (m < 2^NewtonFracBits, r <= 2^(frac + 1)) must fit 128 bits");
  }
  requireAtMost("FactorIntBits", FactorIntBits, "FactorIntBits + ColourFracBits + LobeIntBits",
                FactorIntBits + ColourFracBits + LobeIntBits, "46", 46,
                "the colour code sums the ambient code and per light two terms below 2^(FactorIntBits + "
                "ColourFracBits + LobeIntBits); for up to 63 lights it must stay exact in a double's 53 bits (the "
                "batched path's LSBs)");
  requireAtMost("FactorIntBits", FactorIntBits, "FactorIntBits + ColourFracBits + CosFracBits + 2",
                FactorIntBits + ColourFracBits + CosFracBits + 2, "127", 127,
                "the diffuse product D_k (N.L) must fit 128 bits with its sign");
}

nlohmann::json PhongWidths::toJson() const {
  nlohmann::json j = nlohmann::json::object();
  for (const Member& m : kMembers) j[m.name] = this->*(m.field);
  return j;
}

PhongWidths PhongWidths::fromJson(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object())
    throw std::invalid_argument(fmt::format("{}: the widths must be an object, got {}", where, j.dump()));
  PhongWidths w;
  for (const auto& item : j.items()) {
    const Member* m = findMember(item.key());
    if (m == nullptr)
      throw std::invalid_argument(
          fmt::format("{}: unknown width \"{}\" (known: {})", where, item.key(), knownNames()));
    const nlohmann::json& v = item.value();
    const bool fits = v.is_number_integer() && (v.is_number_unsigned() ? v.get<uint64_t>() <= uint64_t{INT_MAX}
                                                                       : v.get<int64_t>() >= INT_MIN &&
                                                                             v.get<int64_t>() <= INT_MAX);
    if (!fits)
      throw std::invalid_argument(
          fmt::format("{}: width {} must be an integer that fits 32 bits, got {}", where, item.key(), v.dump()));
    w.*(m->field) = v.get<int>();
  }
  try {
    w.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("{}: {}", where, e.what()));
  }
  return w;
}

std::vector<std::string> PhongWidths::names() {
  std::vector<std::string> n;
  for (const Member& m : kMembers) n.emplace_back(m.name);
  return n;
}

namespace {
const Member& memberNamed(const std::string& name) {
  const Member* m = findMember(name);
  if (m == nullptr) throw std::invalid_argument(fmt::format("unknown width \"{}\" (known: {})", name, knownNames()));
  return *m;
}
}  // namespace

int& PhongWidths::at(const std::string& name) { return this->*(memberNamed(name).field); }
int PhongWidths::at(const std::string& name) const { return this->*(memberNamed(name).field); }

bool PhongWidths::operator==(const PhongWidths& o) const {
  for (const Member& m : kMembers)
    if (this->*(m.field) != o.*(m.field)) return false;
  return true;
}

}  // namespace shd
