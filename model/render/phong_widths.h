// The widths of phong-fixed's datapath (render/fixed_shading.h), as runtime parameters: what
// RenderOptions::phong_widths sets for the scalar datapath of render/fixed_widths.h, and what a
// sweep of that datapath varies (sweep/phong_sweep.h). The defaults are the compile-time
// constants of the fixed path (named beside each member), so PhongWidths{} renders exactly the
// images of phong-fixed without widths (test PhongWidths.DefaultsAreBitIdenticalOnEveryScene).
//
// The formats, as the datapath forms them (s: signed, u: unsigned; Qi.f: i integer bits
// including any sign, f fraction bits):
//   N        the interpolated normal: the span unit's attributes 0..2 at NormalFracBits
//            fraction bits (render.cpp's setup; |N| <= 1 for unit vertex normals); |N|^2 at
//            2 NormalFracBits fraction bits, exact, by the recurrence of normalize.h
//   L, H, V  sQ1.UnitFracBits, rounded once per object (per pixel for point lights)
//   N.u      exact, NormalFracBits + UnitFracBits fraction bits
//   1/|N|    |N|^2 = m 4^-shift with m 2^-62 in [1/4, 1); the seed r0 = table[index], the
//            table 2^RsqrtSeedBits entries of round(2^RsqrtSeedFracBits / sqrt(mid)) (uQ1.f,
//            mid the midpoint of the entry's interval of m 2^-62), indexed by the interval;
//            then NewtonSteps steps r' = r (3 - m r^2) / 2 with m truncated to NewtonFracBits
//            fraction bits and each step's m r^2 and r' truncated to NewtonFracBits (r in
//            uQ2.NewtonFracBits; with no step r0 itself, shifted to NewtonFracBits)
//   cosines  N.u r 2^(shift - 31 - UnitFracBits - NewtonFracBits), rounded half up to
//            sQ2.CosFracBits; R.V = 2 (N.L)(N.V) - L.V rounded to the same, L.V once per light
//   lobe     of one cosine: a table over the cosine codes c 2^-LobeCosBits, c = 0..2^LobeCosBits,
//            of f_code = round(f 2^LobeCodeBits) in uQLobeIntBits.LobeCodeBits (saturated at
//            2^(LobeIntBits+LobeCodeBits) - 1), read at the cosine's top LobeCosBits bits and
//            interpolated linearly with its other CosFracBits - LobeCosBits bits, rounded half
//            up; cook-torrance in double from the cosines, then coded the same way
//   factors  D_k = round(255 k_d base_k light_k 2^ColourFracBits), S_k = round(255 k_s light_k
//            2^ColourFracBits), the ambient code alike: uQFactorIntBits.ColourFracBits, saturated
//   colour   D_k (N.L) and S_k f_code rounded half up to ColourFracBits fraction bits (output
//            LSBs), summed with the ambient code, then round(clamp(code 2^-ColourFracBits, 0,
//            255)) plus the specular unit's results (device lobes), clamped to 255
// Every product is formed exactly (the model holds it in 128 bits where 64 do not suffice) and
// rounded or truncated only where the format above says; validate() checks the derivations.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace shd {

struct PhongWidths {
  int NormalFracBits = 28;     // kUnitFrac (pipeline.h): the span unit's normal attributes
  int UnitFracBits = 30;       // kFixedUnitFrac: L, H, V in sQ1.30
  int RsqrtSeedBits = 10;      // kFixedSeedBits: 2^10 seed entries
  int RsqrtSeedFracBits = 16;  // RsqrtSeed's entries, round(2^16 / sqrt(mid))
  int NewtonSteps = 1;         // rsqrtCore's one step (a count, not a width)
  int NewtonFracBits = 32;     // rsqrtCore's mq, m r0^2 and r in Q32
  int CosFracBits = 32;        // the cosines' Q2.32 (cosineScale, the R.V product, L.V)
  int LobeCosBits = 16;        // kFixedCosFrac: the lobe tables' cosine codes
  int LobeCodeBits = 24;       // f_code = round(f 2^24)
  int LobeIntBits = 8;         // f_code saturated at 2^32 - 1 (f < 256)
  int ColourFracBits = 12;     // kFixedColourFrac: colour codes in output LSBs
  int FactorIntBits = 18;      // the factor codes saturated at 2^30 - 1 (2^(18 + 12) - 1)

  // std::invalid_argument naming the width, its value and the derivation it breaks (a range,
  // a shift that must be positive, a product or sum that must fit its container).
  void validate() const;

  // {"ColourFracBits": 12, ...}: every member (a JSON object: in the order of the names).
  nlohmann::json toJson() const;
  // Strict: `j` must be an object whose every member is one of names() holding an integer that
  // fits an int; members left out keep their defaults. Then validate(). std::invalid_argument
  // naming `where` and the member.
  static PhongWidths fromJson(const nlohmann::json& j, const std::string& where);
  static std::vector<std::string> names();  // in the datapath's order, as declared above

  // The member named `name` (one of names()); std::invalid_argument otherwise.
  int& at(const std::string& name);
  int at(const std::string& name) const;

  bool operator==(const PhongWidths& o) const;
  bool operator!=(const PhongWidths& o) const { return !(*this == o); }
};

}  // namespace shd
