#include "cli/command.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace shd::cli {

namespace {

// An error in a configuration file names the file, the member and the value (config/registry.h)
// and is the file's, not the option's; an unknown registry name is the option's.
template <class Load>
auto configArg(const std::string& option, const std::string& arg, Load load) {
  try {
    return load(arg);
  } catch (const std::invalid_argument& e) {
    if (isConfigFile(arg)) throw ArgError(fmt::format("configuration file {}", e.what()));
    throw ArgError(fmt::format("{} {}: {}", option, arg, e.what()));
  }
}

}  // namespace

SpecUnitConfig specConfigArg(const std::string& option, const std::string& arg) {
  return configArg(option, arg, specConfig);
}

SpanUnitConfig spanConfigArg(const std::string& option, const std::string& arg) {
  return configArg(option, arg, spanConfig);
}

std::string configChoices(const std::string& unit) {
  return fmt::format("{} or a JSON file", fmt::join(builtinConfigNames(unit), " | "));
}

}  // namespace shd::cli
