#include "cli/command.h"

#include <cstdio>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "device/prom_io.h"
#include "io/files.h"

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

void writeOut(const std::string& path, const std::string& text) {
  if (path.empty() || path == "-") {
    std::fwrite(text.data(), 1, text.size(), stdout);
    return;
  }
  writeFileAtomic(path, text);
}

}  // namespace shd::cli
