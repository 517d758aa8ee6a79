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

bool existingOrNewDir(const char* option, const std::string& arg, const std::filesystem::path& dir, const char* why) {
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
    throw ArgError(fmt::format("{} {}: not a directory{}", option, arg, why));
  if (std::filesystem::exists(dir, ec)) return true;
  const std::filesystem::path parent = dir.has_parent_path() ? dir.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(parent, ec))
    throw ArgError(fmt::format("{} {}: no such directory, and its parent {} is none either", option, arg, parent.string()));
  return false;
}

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
