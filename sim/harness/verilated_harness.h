// VerilatedHarness<V>: what every DUT harness shares. It owns the VerilatedContext, the model
// and an optional FST waveform, and clocks clk_i. Several models with their own contexts live
// in one process (a traced replay beside the main run), and Verilator 5.006 resolves plusargs,
// $fatal and even ~VerilatedScope through the thread's current context, so the harness makes
// its context current before it evaluates or destroys its model (verilator issue #8265).
#pragma once

#include <atomic>
#include <cstdlib>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <unistd.h>

#include <verilated.h>
#include <verilated_fst_c.h>
#if VM_COVERAGE
#include <verilated_cov.h>
#endif

namespace shd {

namespace harness_detail {
// Whether the model's root (V<prefix>___024root.h, which the adapter includes) has the member in
// which Verilator 5.006's scheduler keeps clk_i as of the previous eval (see cycle()).
template <class R, class = void>
struct HasClkPrev : std::false_type {};
template <class R>
struct HasClkPrev<R, std::void_t<decltype(std::declval<R&>().__Vtrigrprev__TOP__clk_i)>> : std::true_type {};
}  // namespace harness_detail

template <class V>
class VerilatedHarness {
  using Root = std::remove_cv_t<std::remove_pointer_t<decltype(std::declval<V&>().rootp)>>;
  static_assert(sizeof(Root) > 0, "the adapter includes V<prefix>___024root.h before the harness");

 public:
  // cycle() evaluates once per clock cycle (untraced, rst_ni high); otherwise twice.
  static constexpr bool kOneEvalCycles = harness_detail::HasClkPrev<Root>::value;

  VerilatedHarness(const std::vector<std::string>& plusargs, const std::string& fst_path) {
    ctx_ = std::make_unique<VerilatedContext>();
    makeCurrent();
    std::vector<const char*> argv{"shadesim"};
    for (const std::string& a : plusargs) argv.push_back(a.c_str());
    ctx_->commandArgs(static_cast<int>(argv.size()), argv.data());
    if (!fst_path.empty()) ctx_->traceEverOn(true);  // before the model (otherwise Verilator traces nothing)
    dut_ = std::make_unique<V>(ctx_.get(), "dut");
    if (!fst_path.empty()) {
      fst_ = std::make_unique<VerilatedFstC>();
      dut_->trace(fst_.get(), 99);
      fst_->open(fst_path.c_str());
    }
    dut_->clk_i = 0;
    dut_->rst_ni = 1;
  }
  ~VerilatedHarness() {
    finish();
    makeCurrent();
    fst_.reset();
    dut_.reset();
  }
  VerilatedHarness(const VerilatedHarness&) = delete;
  VerilatedHarness& operator=(const VerilatedHarness&) = delete;

  V& dut() { return *dut_; }
  const V& dut() const { return *dut_; }
  void makeCurrent() { Verilated::threadContextp(ctx_.get()); }

  // Evaluates the inputs as they are (clk_i unchanged), e.g. once after construction.
  void settle() {
    makeCurrent();
    dut_->eval();
  }
  // clk_i low, evaluate, half a period, dump: after it, outputs show this cycle's state.
  void fallingEdge() { edge(0); }
  // clk_i high: the registers take their next state.
  void risingEdge() {
    edge(1);
    ++cycle_;
  }
  uint64_t cycle() const { return cycle_; }

  // One whole cycle, for a unit whose outputs are functions of its registers only (no path from
  // an input to an output) and whose only clocked logic is on the rising edge of clk_i (and an
  // asynchronous reset on the falling edge of rst_ni): the caller reads the cycle's outputs
  // before it, then cycle() clocks the inputs as they are in. It is fallingEdge() then
  // risingEdge(), except untraced with rst_ni high: then one eval with clk_i high. Verilator
  // 5.006 finds a rising edge by comparing clk_i with its value at the previous eval, which the
  // falling-edge eval sets to 0; that eval has no other effect on such a unit (nothing is
  // sensitive to the falling edge, and the rising-edge eval evaluates the input logic again), so
  // setting that value (the root's __Vtrigrprev__TOP__clk_i) to 0 instead gives the same
  // rising edge with one eval. A waveform gets both edges. Without that member (another
  // Verilator), it is two evals.
  void cycle() {
    if constexpr (kOneEvalCycles) {
      if (!fst_ && dut_->rst_ni) {
        makeCurrent();
        dut_->rootp->__Vtrigrprev__TOP__clk_i = 0;
        dut_->clk_i = 1;
        dut_->eval();
        ctx_->timeInc(10);
        ++cycle_;
        return;
      }
    }
    fallingEdge();
    risingEdge();
  }

  // Runs final blocks and closes the waveform; called by the destructor too. In a coverage
  // build (cmake -DSHD_COVERAGE=ON) it writes this model's coverage points to
  // $SHD_COVERAGE_DIR/cov_<pid>_<n>.dat when that variable is set (scripts/coverage.sh).
  void finish() {
    if (finished_) return;
    finished_ = true;
    makeCurrent();
    dut_->final();
    if (fst_) fst_->close();
#if VM_COVERAGE
    if (const char* dir = std::getenv("SHD_COVERAGE_DIR")) {
      static std::atomic<unsigned> seq{0};
      const std::string path =
          std::string(dir) + "/cov_" + std::to_string(getpid()) + "_" + std::to_string(seq++) + ".dat";
      ctx_->coveragep()->write(path.c_str());
    }
#endif
  }

 private:
  void edge(int level) {
    makeCurrent();
    dut_->clk_i = level;
    dut_->eval();
    ctx_->timeInc(5);
    if (fst_) fst_->dump(ctx_->time());
  }

  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<V> dut_;
  std::unique_ptr<VerilatedFstC> fst_;
  uint64_t cycle_ = 0;
  bool finished_ = false;
};

}  // namespace shd
