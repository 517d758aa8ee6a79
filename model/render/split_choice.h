// SplitChoice: RenderOptions::Split::Auto's choice between a two-thread frame split by rows and
// one split into front and back end, measured over the frames drawn into one RenderResult (a
// benchmark, an animation). Both ways give the same bytes and counts (test_render.cpp); which is
// faster depends on the method, the scene and the machine, and on this project's VMs it changed
// within minutes (docs/performance.md, "Two threads"), so it is measured rather than fixed.
//
// The frames run in cycles of kCycle. A cycle draws its frames the chosen way, except its last
// kProbe, drawn the other way. At the cycle's end the fastest of those probe frames is compared
// with the fastest of the kProbe chosen frames just before them (the same number of frames, next
// to each other in time); the other way is chosen for the next cycle when it was faster. The
// first frame is drawn the way the caller prefers. The cost: kProbe of kCycle frames the slower
// way, when it is the slower.
#pragma once

#include <limits>

namespace shd {

class SplitChoice {
 public:
  static constexpr int kCycle = 32, kProbe = 2;

  // The way of the next frame: true by rows. `prefer_rows`: the way of the first frame.
  bool next(bool prefer_rows) {
    if (k_ < 0) {
      rows_ = prefer_rows;
      k_ = 0;
    }
    return k_ >= kCycle - kProbe ? !rows_ : rows_;
  }
  // The time of the frame next() gave the way of, drawn that way.
  void record(double ms) {
    if (k_ < 0) return;
    if (k_ >= kCycle - 2 * kProbe) {
      double& best = k_ >= kCycle - kProbe ? probe_ : chosen_;
      if (ms < best) best = ms;
    }
    if (++k_ < kCycle) return;
    if (probe_ < chosen_) rows_ = !rows_;
    k_ = 0;
    chosen_ = probe_ = std::numeric_limits<double>::infinity();
  }
  bool rows() const { return rows_; }  // the way chosen for the current cycle

 private:
  int k_ = -1;  // the frame's place in its cycle; -1 before the first frame
  bool rows_ = false;
  double chosen_ = std::numeric_limits<double>::infinity(), probe_ = std::numeric_limits<double>::infinity();
};

}  // namespace shd
