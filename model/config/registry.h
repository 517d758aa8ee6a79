// The unit configurations: every vectors/config/<unit>_<name>.json of the build (the registry;
// CMake may add directories with SHD_CONFIG_DIRS), embedded as text at build time by
// scripts/shd_config.py so that an installed binary needs no source tree; and any configuration
// file a user writes, read the same way.
//
// A configuration file (units "spec": rtl/shd_spec_unit.v, "span": rtl/shd_span_unit.v):
//   { "name": "<name>",                      // lower-case letters and digits, as in the file name
//     "description": "...",                  // free text
//     "rtl":  { "<Parameter>": <integer> },  // the Verilog parameters of the unit's top module
//     "prom": { "fit": ..., "level": ..., "n": ... },    // spec only: the PROM's contents
//     "expected": { "<group>": { "<figure>": <number> } } }  // optional: the figures
//                                        // scripts/regress.py checks (docs/configurations.md)
// CMake verilates one model per registry file with every member of "rtl" as -G<Name>=<value>
// (scripts/shd_config.py makes the options of Verilator, Icarus and yosys); the model reads the
// same members here. A span configuration is a lane mode: its name is the mode's name and its
// lane layout is its NumTri, LanesPerTri and AlignLanes.
#pragma once

#include <string>
#include <vector>

#include "device/spec_params.h"
#include "raster/span_unit.h"

namespace shd {

struct BuiltinConfig {
  const char* unit;  // "spec" | "span"
  const char* name;
  const char* file;  // the file it was embedded from (relative to the source tree inside it)
  const char* json;  // the file's text
};

// The registry of this build, sorted by unit, then by name.
const std::vector<BuiltinConfig>& builtinConfigs();
std::vector<std::string> builtinConfigNames(const std::string& unit);

struct SpecUnitConfig {
  std::string name, description;
  std::string path;      // the file it came from: a user's file, or the registry's (BuiltinConfig::file)
  bool builtin = false;  // from the registry (specConfig() by name)
  SpecUnitParams rtl;
  PromContent prom;
  // "inputs": {"cos_code_min": [...]}, optional: per PROM entry the least cosine code the
  // configuration was sized for (shadesim prune); the models rendering with it refuse a lower one
  // (modelSpecEngine, render/lobe_units.h). Empty: every code.
  std::vector<uint32_t> cos_code_min;

  // What --config takes to name it again: the registry name, or the file.
  const std::string& ref() const { return builtin ? name : path; }

  // std::invalid_argument naming `where` and the member for anything malformed or out of range.
  static SpecUnitConfig parse(const std::string& json_text, const std::string& where);
};

struct SpanUnitConfig {
  std::string name, description;
  std::string path;
  bool builtin = false;
  SpanParams rtl;  // every member required

  const std::string& ref() const { return builtin ? name : path; }

  static SpanUnitConfig parse(const std::string& json_text, const std::string& where);
};

// True when `arg` names a file rather than a registry name: it contains '/', ends in ".json" or
// is an existing file.
bool isConfigFile(const std::string& arg);

// A registry name or a JSON file. std::invalid_argument for an unknown name (listing the
// registry's), an unreadable file, or the errors of parse().
SpecUnitConfig specConfig(const std::string& name_or_file);
SpanUnitConfig spanConfig(const std::string& name_or_file);

}  // namespace shd
