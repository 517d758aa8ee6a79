// Progress of a long run on stderr: a line rewritten in place on a terminal, one line per
// tenth of the work otherwise (CI logs).
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

#include <unistd.h>

namespace shd {

class Progress {
 public:
  Progress(std::string what, bool enabled)
      : what_(std::move(what)), enabled_(enabled), tty_(isatty(fileno(stderr)) != 0),
        t0_(std::chrono::steady_clock::now()) {}

  void update(double done, double total, const char* unit) {
    if (!enabled_ || total <= 0) return;
    const double frac = done / total;
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    if (!tty_) {
      const int tenth = static_cast<int>(frac * 10);
      if (tenth <= last_tenth_) return;
      last_tenth_ = tenth;
    }
    std::fprintf(stderr, "%s%s: %5.1f %% (%.0f / %.0f %s, %.1f s, %.3g %s/s)%s", tty_ ? "\r" : "", what_.c_str(),
                 100 * frac, done, total, unit, secs, secs > 0 ? done / secs : 0.0, unit, tty_ ? "" : "\n");
    std::fflush(stderr);
    drawn_ = true;
  }

  ~Progress() {
    if (drawn_ && tty_) std::fprintf(stderr, "\n");
  }

 private:
  std::string what_;
  bool enabled_, tty_;
  std::chrono::steady_clock::time_point t0_;
  int last_tenth_ = -1;
  bool drawn_ = false;
};

}  // namespace shd
