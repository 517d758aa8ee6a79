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
#include <vector>

#include <unistd.h>

#include <verilated.h>
#include <verilated_fst_c.h>
#if VM_COVERAGE
#include <verilated_cov.h>
#endif

namespace shd {

template <class V>
class VerilatedHarness {
 public:
  VerilatedHarness(const std::vector<std::string>& plusargs, const std::string& fst_path) {
    ctx_ = std::make_unique<VerilatedContext>();
    makeCurrent();
    std::vector<const char*> argv{"shadesim"};
    for (const std::string& a : plusargs) argv.push_back(a.c_str());
    ctx_->commandArgs(static_cast<int>(argv.size()), argv.data());
    if (!fst_path.empty()) ctx_->traceEverOn(true);  // before the model (TOOLCHAIN 4)
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
