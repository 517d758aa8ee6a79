#include "sc_fail_case.h"


#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "io/process.h"

namespace shd {

namespace {

// The program's own executable: the kernel's link (independent of the current directory and
// PATH), else argv[0].
std::string selfExe(const ScOptions& o) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? o.argv0 : p.string();
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

}  // namespace

std::string ScFailReplay::command() const {
  std::string c;
  for (const std::string& a : argv) {
    if (!c.empty()) c += ' ';
    c += a.find_first_of(" \t'\"\\$*?;&|<>()") == std::string::npos ? a : "'" + a + "'";
  }
  return c;
}

ScFailReplay replayFailCase(const ScOptions& o, const ScFailCase& c) {
  ScFailReplay r;
  r.argv = {selfExe(o), "--unit", o.unit, "--config", o.config, "--vector-file", c.vec, "--fst", c.fst,
            "--json", "--quiet", "--no-fail-save"};
  std::error_code ec;
  std::filesystem::remove(c.fst, ec);  // an old waveform must not pass for this one
  std::string out, err;
  r.status = runProcess(r.argv, out, err, r.error);
  r.fst_written = std::filesystem::file_size(c.fst, ec) > 0 && !ec;
  if (r.status < 0) {
    if (!err.empty()) r.error += "; its stderr: " + trimmed(err);
    return r;
  }
  if (r.status != 0 && r.status != 1) {  // bad input, or an abort (a sanitizer report)
    r.error = fmt::format("exit status {}: {}", r.status, trimmed(err));
    return r;
  }
  try {
    const nlohmann::json j = nlohmann::json::parse(out);
    r.mismatch_cycle = j.value("mismatch_file_cycle", uint64_t{0});
    r.file_mismatch_cycle = j.value("file_mismatch_cycle", uint64_t{0});
    r.first = j.value("first_mismatch", std::string());
    if (r.first.empty()) r.first = j.value("first_item_mismatch", std::string());
  } catch (const std::exception& e) {
    r.error = fmt::format("no result from the replay ({}); exit status {}, stderr: {}", e.what(), r.status, trimmed(err));
  }
  return r;
}

}  // namespace shd
