#include "config/registry.h"
#include "device/prom.h"
#include "io/files.h"
#include "io/json_strict.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

namespace shd {

namespace config_detail {
// Generated at configure time (scripts/shd_config.py cmake): the registry's files.
extern const BuiltinConfig kBuiltin[];
extern const size_t kBuiltinCount;
}  // namespace config_detail

namespace {

nlohmann::json parseObject(const std::string& text, const std::string& where) {
  nlohmann::json j;
  try {
    j = parseJsonStrict(text);
  } catch (const nlohmann::json::exception& e) {  // parse_error; out_of_range for 1e999
    throw std::invalid_argument(fmt::format("{}: not valid JSON: {}", where, e.what()));
  } catch (const std::invalid_argument& e) {  // a repeated key
    throw std::invalid_argument(fmt::format("{}: {}", where, e.what()));
  }
  if (!j.is_object()) throw std::invalid_argument(fmt::format("{}: must hold a JSON object", where));
  return j;
}

std::string stringMember(const nlohmann::json& v, const std::string& where, const char* key) {
  if (!v.is_string()) throw std::invalid_argument(fmt::format("{}: \"{}\" must be a string", where, key));
  return v.get<std::string>();
}

PromContent promFromJson(const nlohmann::json& value, const std::string& where) {
  if (!value.is_object()) throw std::invalid_argument(fmt::format("{}: prom must be an object", where));
  PromContent c;
  for (const auto& [pk, pv] : value.items()) {
    if (pk == "fit" && pv.is_string()) c.fit = pv.get<std::string>();
    else if (pk == "level" && pv.is_number()) {
      c.level = pv.get<double>();
      if (!(c.level > 0 && c.level < 1))
        throw std::invalid_argument(fmt::format("{}: prom.level = {} must lie in (0, 1)", where, pv.dump()));
    } else if (pk == "n" && pv.is_string()) c.n = pv.get<std::string>();
    else if (pk == "n_list" && pv.is_string()) {
      c.n = pv.get<std::string>();
      c.is_list = true;
    } else {
      throw std::invalid_argument(fmt::format(
          "{}: prom.{} is unknown or has the wrong type (fit: string, level: number, n or n_list: string)", where, pk));
    }
  }
  if (!value.contains("fit")) throw std::invalid_argument(fmt::format("{}: prom.fit missing", where));
  if (value.contains("n") == value.contains("n_list"))
    throw std::invalid_argument(fmt::format("{}: prom needs exactly one of n (a range) and n_list", where));
  return c;
}

// The figures "expected" may record (scripts/regress.py computes and checks them; the table is
// also in scripts/shd_config.py, EXPECTED): group -> figure names; a group with no figure names
// is itself one number.
struct ExpectedGroup {
  const char* group;
  std::vector<const char*> figures;
};
const std::vector<ExpectedGroup>& expectedGroups(const std::string& unit) {
  static const std::vector<const char*> area = {"luts", "ffs", "carries", "dsps", "brams"};
  static const std::vector<const char*> spec_scene = {"spec_cycles", "spec_evaluations", "max_abs_lsb"};
  static const std::vector<const char*> span_scene = {"cycles", "fragments"};
  static const std::vector<ExpectedGroup> spec = {
      {"error", {"total_max_lsb", "total_peak_max_lsb", "datapath_max_lsb", "datapath_max_f_lsb"}},
      {"latency", {}},
      {"sphere", spec_scene},
      {"still_life", spec_scene},
      {"ice40", area},
      {"xc7", area}};
  static const std::vector<ExpectedGroup> span = {
      {"sphere", span_scene}, {"still_life", span_scene}, {"ice40", area}, {"xc7", area}};
  return unit == "spec" ? spec : span;
}

// "expected": the figures the configuration is known to reach; only its shape is checked here.
void checkExpected(const nlohmann::json& value, const std::string& where, const std::string& unit) {
  if (!value.is_object())
    throw std::invalid_argument(fmt::format("{}: \"expected\" must be an object of figure groups", where));
  const auto& groups = expectedGroups(unit);
  for (const auto& [gk, gv] : value.items()) {
    const auto g =
        std::find_if(groups.begin(), groups.end(), [&key = gk](const ExpectedGroup& e) { return key == e.group; });
    if (g == groups.end()) {
      std::vector<std::string> names;
      for (const ExpectedGroup& e : groups) names.emplace_back(e.group);
      throw std::invalid_argument(
          fmt::format("{}: expected.{}: unknown group (known: {})", where, gk, fmt::join(names, ", ")));
    }
    if (g->figures.empty()) {
      if (!gv.is_number())
        throw std::invalid_argument(fmt::format("{}: expected.{} = {} is not a number", where, gk, gv.dump()));
      continue;
    }
    if (!gv.is_object())
      throw std::invalid_argument(fmt::format("{}: expected.{} must be an object of figures", where, gk));
    for (const auto& [fk, fv] : gv.items()) {
      if (std::find_if(g->figures.begin(), g->figures.end(), [&key = fk](const char* f) { return key == f; }) ==
          g->figures.end())
        throw std::invalid_argument(fmt::format("{}: expected.{}.{}: unknown figure (known: {})", where, gk, fk,
                                                fmt::join(g->figures, ", ")));
      if (!fv.is_number())
        throw std::invalid_argument(
            fmt::format("{}: expected.{}.{} = {} is not a number", where, gk, fk, fv.dump()));
    }
  }
}

std::string readFile(const std::string& path) {
  try {
    return readInputFile(path, uint64_t{1} << 20);  // a configuration is a few hundred bytes
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument(e.what());
  }
}

// The registry entry or the file, parsed by Config::parse.
template <class Config>
Config resolve(const std::string& unit, const char* unit_label, const std::string& arg) {
  if (isConfigFile(arg)) return Config::parse(readFile(arg), arg);
  for (const BuiltinConfig& b : builtinConfigs())
    if (unit == b.unit && arg == b.name) {
      Config c = Config::parse(b.json, b.file);
      c.builtin = true;
      return c;
    }
  throw std::invalid_argument(fmt::format("no {} configuration '{}' (built in: {}; or give a JSON file)", unit_label, arg,
                                          fmt::join(builtinConfigNames(unit), ", ")));
}

}  // namespace

const std::vector<BuiltinConfig>& builtinConfigs() {
  static const std::vector<BuiltinConfig> all(config_detail::kBuiltin,
                                              config_detail::kBuiltin + config_detail::kBuiltinCount);
  return all;
}

std::vector<std::string> builtinConfigNames(const std::string& unit) {
  std::vector<std::string> names;
  for (const BuiltinConfig& b : builtinConfigs())
    if (unit == b.unit) names.emplace_back(b.name);
  return names;
}

namespace {

// "inputs": {"cos_code_min": [codes]}: non-negative integers below 2^25 (CosFracBits <= 24).
std::vector<uint32_t> cosCodeMin(const nlohmann::json& v, const std::string& where) {
  if (!v.is_object() || v.size() != 1 || !v.contains("cos_code_min") || !v["cos_code_min"].is_array() ||
      v["cos_code_min"].empty())
    throw std::invalid_argument(fmt::format("{}: inputs: must be {{\"cos_code_min\": [a code per PROM entry]}}", where));
  std::vector<uint32_t> out;
  for (const nlohmann::json& c : v["cos_code_min"]) {
    if (!c.is_number_unsigned() || c.get<uint64_t>() >= (uint64_t{1} << 25))
      throw std::invalid_argument(fmt::format("{}: inputs.cos_code_min: {} is not a cosine code (0 .. 2^25 - 1)", where, c.dump()));
    out.push_back(c.get<uint32_t>());
  }
  return out;
}

}  // namespace

SpecUnitConfig SpecUnitConfig::parse(const std::string& text, const std::string& where) {
  const nlohmann::json j = parseObject(text, where);
  SpecUnitConfig c;
  c.path = where;
  bool has_rtl = false, has_prom = false;
  for (const auto& [key, value] : j.items()) {
    if (key == "name") c.name = stringMember(value, where, "name");
    else if (key == "description") c.description = stringMember(value, where, "description");
    else if (key == "rtl") c.rtl = SpecUnitParams::fromJson(value, where), has_rtl = true;
    else if (key == "prom") c.prom = promFromJson(value, where), has_prom = true;
    else if (key == "expected") checkExpected(value, where, "spec");
    else if (key == "inputs") c.cos_code_min = cosCodeMin(value, where);
    else throw std::invalid_argument(fmt::format("{}: unknown key \"{}\"", where, key));
  }
  // A file states the whole unit: nothing falls back to a default the user did not see.
  if (c.name.empty()) throw std::invalid_argument(fmt::format("{}: missing \"name\"", where));
  if (!has_rtl) throw std::invalid_argument(fmt::format("{}: missing \"rtl\" (the Verilog parameters)", where));
  if (!has_prom) throw std::invalid_argument(fmt::format("{}: missing \"prom\" (fit and shininess list)", where));
  try {
    checkFitForKind(PromRequest::fromContent(c.prom).fit, c.rtl);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("{}: prom: {}", where, e.what()));
  }
  return c;
}

SpanUnitConfig SpanUnitConfig::parse(const std::string& text, const std::string& where) {
  const nlohmann::json j = parseObject(text, where);
  SpanUnitConfig c;
  c.path = where;
  bool has_rtl = false;
  for (const auto& [key, value] : j.items()) {
    if (key == "name") c.name = stringMember(value, where, "name");
    else if (key == "description") c.description = stringMember(value, where, "description");
    else if (key == "rtl") c.rtl = SpanParams::fromJson(value, where), has_rtl = true;
    else if (key == "expected") checkExpected(value, where, "span");
    else throw std::invalid_argument(fmt::format("{}: unknown key \"{}\"", where, key));
  }
  if (c.name.empty()) throw std::invalid_argument(fmt::format("{}: missing \"name\"", where));
  if (!has_rtl) throw std::invalid_argument(fmt::format("{}: missing \"rtl\"", where));
  return c;
}

bool isConfigFile(const std::string& arg) {
  const bool json_suffix = arg.size() >= 5 && arg.compare(arg.size() - 5, 5, ".json") == 0;
  std::error_code ec;
  return arg.find('/') != std::string::npos || json_suffix || std::filesystem::is_regular_file(arg, ec);
}

SpecUnitConfig specConfig(const std::string& arg) { return resolve<SpecUnitConfig>("spec", "specular-unit", arg); }
SpanUnitConfig spanConfig(const std::string& arg) { return resolve<SpanUnitConfig>("span", "span-unit", arg); }

}  // namespace shd
