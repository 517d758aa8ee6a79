// Input streams for the specular unit: every input exhaustively, or seeded random vectors with
// valid gaps. Pure model code, shared by the C++ co-simulation (sim/cosim/spec_cosim.h), the vector
// file generator and the SystemC testbench.
#pragma once

#include <cstdint>
#include <random>

#include "device/spec_unit.h"

namespace shd {

// Produces the input of each cycle. Returns false when the stream ends.
class SpecStimulus {
 public:
  virtual ~SpecStimulus() = default;
  virtual bool next(SpecIn& in) = 0;
  virtual uint64_t total() const = 0;  // valid vectors the stream will produce
};

// Every (shininess code, cos code) pair, cos codes 0 .. 2^(Wc+1)-1 (those above 1.0 test the
// input saturation), valid on every cycle; light channels seeded random, one vector in eight
// at full scale.
class ExhaustiveSpecStimulus final : public SpecStimulus {
 public:
  ExhaustiveSpecStimulus(const SpecUnitParams& p, uint64_t seed);
  bool next(SpecIn& in) override;
  uint64_t total() const override;

 private:
  SpecUnitParams p_;
  std::mt19937_64 rng_;
  uint64_t index_ = 0;
};

// Seeded random vectors: shininess uniform over the PROM, cos uniform with one vector in four
// in the last 1/64 of the range (the narrow lobes of large n) and one in 32 above 1.0; valid
// dropped with probability gap_prob for 1..3 cycles at a time.
class RandomSpecStimulus final : public SpecStimulus {
 public:
  RandomSpecStimulus(const SpecUnitParams& p, uint64_t seed, uint64_t vectors, double gap_prob);
  bool next(SpecIn& in) override;
  uint64_t total() const override { return vectors_; }

 private:
  SpecUnitParams p_;
  std::mt19937_64 rng_;
  uint64_t vectors_;
  uint64_t sent_ = 0;
  double gap_prob_;
  int gap_left_ = 0;
};

}  // namespace shd
