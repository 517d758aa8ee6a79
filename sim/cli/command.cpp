#include "cli/command.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace shd::cli {

SpecUnitConfig specConfigArg(const std::string& option, const std::string& arg) {
  try {
    return specConfig(arg);
  } catch (const std::invalid_argument& e) {
    throw ArgError(fmt::format("{} {}: {}", option, arg, e.what()));
  }
}

SpanUnitConfig spanConfigArg(const std::string& option, const std::string& arg) {
  try {
    return spanConfig(arg);
  } catch (const std::invalid_argument& e) {
    throw ArgError(fmt::format("{} {}: {}", option, arg, e.what()));
  }
}

std::string configChoices(const std::string& unit) {
  return fmt::format("{} or a JSON file", fmt::join(builtinConfigNames(unit), " | "));
}

}  // namespace shd::cli
