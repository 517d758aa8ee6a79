// What the command lines of both programs (shadesim, shadesim_systemc) share: the exit status,
// strict numeric options with stated limits, and the format of a parse error. docs/files.md
// documents the policy.
//
// Numbers. CLI11 (2.1) converts with strtoull/strtod and checks ranges with comparisons, so it
// takes "nan" and "inf" (every comparison with NaN is false), wraps "99999999999999999999" to
// 2^64 - 1, reads "0x10" as 16 and "-5" as a huge unsigned value. Every numeric option of both
// programs is checked first by one of the validators below, on the text as typed: a count is
// decimal digits only, a real is a finite decimal number; both must lie in the option's stated
// range. CLI11's own conversion runs only on text that passed.
#pragma once

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

namespace shd::cli {

// Exit status, the same for both programs.
constexpr int kExitOk = 0;        // the run completed and every check passed
constexpr int kExitFailed = 1;    // the run completed and a check failed (a mismatch)
constexpr int kExitBadInput = 2;  // the run could not be done: bad input, a refused output, a
                                  // resource limit, an I/O error (one "error:" line on stderr)

// A usage error: the message names the option and the value.
struct ArgError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The limits both programs state for the same quantity.
constexpr uint64_t kMaxStreamTriangles = 1'000'000'000;  // random triangles streamed through a
                                                          // co-simulation (tags are 32 bits; at
                                                          // about 1e5 triangles/s: 3 hours)
constexpr uint64_t kMaxVectors = 10'000'000'000;          // random specular vectors (about 1 hour)
constexpr double kMinReady = 0.05;                        // consumer-ready probability, at least
constexpr double kMaxGap = 0.9;                           // probabilities of a gap in the input

// Options of `app` that do not apply in this run (given though another option rules them out):
// ArgError "<option> <why>" for the first one given.
inline void requireAbsent(const CLI::App& app, std::initializer_list<const char*> options, const std::string& why) {
  for (const char* o : options)
    if (app.count(o) > 0) throw ArgError(fmt::format("{} {}", o, why));
}

// A comma-separated list option (--modes, --drop, --pnr-devices) names each entry once:
// ArgError "<option>: <entry> is named twice" when `entry` is in `names` more than once.
inline void refuseRepeat(const char* option, const std::vector<std::string>& names, const std::string& entry) {
  if (std::count(names.begin(), names.end(), entry) > 1) throw ArgError(fmt::format("{}: {} is named twice", option, entry));
}

// A directory option (--fail-dir): an existing directory; ArgError otherwise. The programs
// write into directories, they do not create them (io/files.h).
inline void requireDirectoryArg(const char* option, const std::string& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw ArgError(fmt::format("{} {}: {}", option, dir,
                               std::filesystem::exists(dir, ec) ? "not a directory" : "no such directory"));
}

// An integer option: decimal digits only, in [lo, hi].
inline CLI::Validator countIn(uint64_t lo, uint64_t hi) {
  const std::string range = fmt::format("a whole number in [{}, {}]", lo, hi);
  return CLI::Validator(
      [lo, hi, range](std::string& s) -> std::string {
        // 20 digits hold every 64-bit value; longer is out of range anyway.
        bool digits = !s.empty() && s.size() <= 20;
        for (char ch : s) digits = digits && ch >= '0' && ch <= '9';
        if (!digits) return fmt::format("'{}' is not {}", s, range);
        errno = 0;
        const unsigned long long v = std::strtoull(s.c_str(), nullptr, 10);
        if (errno == ERANGE || v < lo || v > hi) return fmt::format("{} is out of range: must be {}", s, range);
        return {};
      },
      fmt::format("INT in [{}, {}]", lo, hi));
}

// A real option: a finite decimal number in [lo, hi], or in (lo, hi] / [lo, hi) / (lo, hi)
// with the open ends named.
enum class Ends { Closed, OpenLow, OpenHigh, Open };
inline CLI::Validator realIn(double lo, double hi, Ends ends = Ends::Closed) {
  const bool open_lo = ends == Ends::OpenLow || ends == Ends::Open;
  const bool open_hi = ends == Ends::OpenHigh || ends == Ends::Open;
  const std::string range = fmt::format("{}{}, {}{}", open_lo ? '(' : '[', lo, hi, open_hi ? ')' : ']');
  return CLI::Validator(
      [lo, hi, open_lo, open_hi, range](std::string& s) -> std::string {
        // strtod also takes "nan", "inf", hexadecimal and leading spaces: only a plain decimal
        // (sign, digits, one point, exponent) is a number here.
        const bool plain = !s.empty() && s.find_first_not_of("+-0123456789.eE") == std::string::npos;
        char* end = nullptr;
        errno = 0;
        const double v = plain ? std::strtod(s.c_str(), &end) : NAN;
        if (!plain || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v))
          return fmt::format("'{}' is not a finite number (must lie in {})", s, range);
        if (v < lo || v > hi || (open_lo && v == lo) || (open_hi && v == hi))
          return fmt::format("{} is out of range: must lie in {}", s, range);
        return {};
      },
      fmt::format("NUMBER in {}", range));
}

// A CLI11 parse error as both programs report errors: --help and --version print and return 0;
// anything else prints "<who>: error: <what>" and a hint on stderr and returns kExitBadInput
// (never CLI11's own codes 105, 106, ...).
inline int parseErrorExit(const CLI::App& app, const CLI::ParseError& e, const std::string& who) {
  if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
  std::fprintf(stderr, "%s: error: %s\nRun with --help for the options.\n", who.c_str(), e.what());
  return kExitBadInput;
}

}  // namespace shd::cli
