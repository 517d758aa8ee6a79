#include "device/spec_stimulus.h"

namespace shd {

ExhaustiveSpecStimulus::ExhaustiveSpecStimulus(const SpecUnitParams& p, uint64_t seed) : p_(p), rng_(seed) {}

uint64_t ExhaustiveSpecStimulus::total() const {
  return static_cast<uint64_t>(p_.shinCodes()) << (p_.CosFracBits + 1);
}

bool ExhaustiveSpecStimulus::next(SpecIn& in) {
  if (index_ >= total()) return false;
  const int cos_bits = p_.CosFracBits + 1;
  in.valid = true;
  in.shin = static_cast<uint32_t>(index_ >> cos_bits);
  in.cos = static_cast<uint32_t>(index_ & ((uint64_t{1} << cos_bits) - 1));
  const uint64_t r = rng_();
  const uint32_t lmask = static_cast<uint32_t>(p_.lightMax());
  const bool full = (r >> 61) == 0;  // one in eight
  for (int k = 0; k < 3; ++k)
    in.light[k] = full ? lmask : static_cast<uint32_t>(r >> (16 * k)) & lmask;
  ++index_;
  return true;
}

RandomSpecStimulus::RandomSpecStimulus(const SpecUnitParams& p, uint64_t seed, uint64_t vectors, double gap_prob)
    : p_(p), rng_(seed), vectors_(vectors), gap_prob_(gap_prob) {}

bool RandomSpecStimulus::next(SpecIn& in) {
  if (sent_ >= vectors_) return false;
  if (gap_left_ == 0 && gap_prob_ > 0 && std::uniform_real_distribution<double>(0, 1)(rng_) < gap_prob_)
    gap_left_ = 1 + static_cast<int>(rng_() % 3);
  const uint64_t r = rng_();
  const uint32_t one = static_cast<uint32_t>(p_.cosOne());
  // Inputs change on idle cycles too: the unit must ignore them.
  in.shin = static_cast<uint32_t>(r % static_cast<uint64_t>(p_.shinCodes()));
  const uint64_t r2 = rng_();
  const unsigned sel = static_cast<unsigned>(r2 & 31);
  if (sel == 0) in.cos = one + static_cast<uint32_t>((r2 >> 8) % one);            // above 1.0
  else if (sel < 9) in.cos = one - static_cast<uint32_t>((r2 >> 8) % (one / 64 + 1));  // near 1
  else in.cos = static_cast<uint32_t>((r2 >> 8) % (one + 1));
  const uint32_t lmask = static_cast<uint32_t>(p_.lightMax());
  for (int k = 0; k < 3; ++k) in.light[k] = static_cast<uint32_t>(r >> (20 + 12 * k)) & lmask;
  if (gap_left_ > 0) {
    --gap_left_;
    in.valid = false;
    return true;
  }
  in.valid = true;
  ++sent_;
  return true;
}

}  // namespace shd
