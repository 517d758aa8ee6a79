// The "rtl" object of a configuration read into (and written from) a parameter struct whose
// members are ints named as the Verilog parameters: SpecUnitParams, SpanParams.
#pragma once

#include <climits>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace shd {

template <class P>
struct ParamMember {
  const char* name;
  int P::*field;
  bool optional = false;  // may be omitted: keeps the struct's default, which is the Verilog default
};

// Every member of `rtl` must be one of `members` and an integer that fits an int; with
// all_required every one of `members` that is not optional must be present (otherwise the
// struct's defaults stay).
// Then P::validate(). std::invalid_argument naming `where` and the member.
template <class P, size_t N>
P paramsFromJson(const nlohmann::json& rtl, const ParamMember<P> (&members)[N], bool all_required,
                 const std::string& where) {
  if (!rtl.is_object()) throw std::invalid_argument(fmt::format("{}: \"rtl\" must be an object", where));
  P p;
  for (const auto& item : rtl.items()) {
    const std::string& key = item.key();
    const nlohmann::json& value = item.value();
    const ParamMember<P>* m = nullptr;
    for (const ParamMember<P>& cand : members)
      if (key == cand.name) m = &cand;
    if (m == nullptr) {
      std::string known;
      for (const ParamMember<P>& k : members) known += std::string(known.empty() ? "" : " ") + k.name;
      throw std::invalid_argument(fmt::format("{}: unknown parameter rtl.{} (known: {})", where, key, known));
    }
    const bool fits = value.is_number_integer() &&
                      (value.is_number_unsigned() ? value.get<uint64_t>() <= uint64_t{INT_MAX}
                                                  : value.get<int64_t>() >= INT_MIN && value.get<int64_t>() <= INT_MAX);
    if (!fits) throw std::invalid_argument(fmt::format("{}: rtl.{} must be an integer that fits 32 bits, got {}", where, key, value.dump()));
    p.*(m->field) = value.get<int>();
  }
  if (all_required)
    for (const ParamMember<P>& m : members)
      if (!m.optional && !rtl.contains(m.name)) throw std::invalid_argument(fmt::format("{}: rtl.{} missing", where, m.name));
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("{}: {}", where, e.what()));
  }
  return p;
}

template <class P, size_t N>
nlohmann::json paramsToJson(const P& p, const ParamMember<P> (&members)[N]) {
  nlohmann::json j = nlohmann::json::object();
  for (const ParamMember<P>& m : members) j[m.name] = p.*(m.field);
  return j;
}

}  // namespace shd
