#include "render/methods.h"

#include <iterator>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "render/draw.h"

namespace shd {

// The units, render/methods/<file>.cpp.
std::unique_ptr<MethodUnit> makeFlatUnit(Frame& f);                // colour_runs.cpp
std::unique_ptr<MethodUnit> makeGouraudUnit(Frame& f);             // colour_runs.cpp
std::unique_ptr<MethodUnit> makeGouraudClassicalUnit(Frame& f);    // gouraud_classical.cpp
std::unique_ptr<MethodUnit> makePhongUnit(Frame& f);               // phong.cpp
std::unique_ptr<MethodUnit> makePhongIncrementalUnit(Frame& f);    // phong.cpp
std::unique_ptr<MethodUnit> makePhongFixedUnit(Frame& f);          // phong_fixed.cpp
std::unique_ptr<MethodUnit> makeNormalBisectionUnit(Frame& f);     // phong.cpp
std::unique_ptr<MethodUnit> makeBiquadraticUnit(Frame& f);         // biquadratic.cpp
std::unique_ptr<MethodUnit> makeModifiedGouraudUnit(Frame& f);     // modified_gouraud.cpp
std::unique_ptr<MethodUnit> makeAdaptiveUnit(Frame& f);            // adaptive.cpp
std::unique_ptr<MethodUnit> makeReferenceUnit(Frame& f);           // reference.cpp

namespace {
constexpr Attributes C = Attributes::Colour, N = Attributes::Normal;
constexpr TwoThreads No = TwoThreads::No, Setup = TwoThreads::AfterSetup, Walk = TwoThreads::AfterWalk;
}  // namespace

// In Method's order. The walk of each unit: colour runs (flat, gouraud; AVX-512 where the CPU
// has it), fixed-point runs and the vector kernel's batch (phong-fixed), fragment by fragment
// as the walk produces them (gouraud-classical, phong, phong-incremental, biquadratic), whole
// rows collected first (normal-bisection), the edge functions directly (reference).
// modified-gouraud and adaptive draw their parts with the gouraud and phong units (their own
// attributes are never set up).
constexpr MethodTraits kMethodTable[] = {
    // method                  name                 attr vertex faces  pixel  exact  2 threads rows  unit
    {Method::Flat,             "flat",              C, false, true,   false, false, Setup,  true,  makeFlatUnit},
    {Method::Gouraud,          "gouraud",           C, true,  false,  false, false, Setup,  true,  makeGouraudUnit},
    {Method::GouraudClassical, "gouraud-classical", C, true,  false,  false, false, No,     false, makeGouraudClassicalUnit},
    {Method::Phong,            "phong",             N, false, false,  true,  false, No,     true,  makePhongUnit},
    {Method::PhongIncremental, "phong-incremental", N, false, false,  true,  false, No,     true,  makePhongIncrementalUnit},
    {Method::PhongFixed,       "phong-fixed",       N, false, false,  true,  false, Walk,   true,  makePhongFixedUnit},
    {Method::NormalBisection,  "normal-bisection",  N, false, false,  true,  false, No,     false, makeNormalBisectionUnit},
    {Method::Biquadratic,      "biquadratic",       C, true,  false,  false, false, No,     false, makeBiquadraticUnit},
    {Method::ModifiedGouraud,  "modified-gouraud",  C, true,  false,  false, false, No,     false, makeModifiedGouraudUnit},
    {Method::Adaptive,         "adaptive",          N, true,  false,  false, false, No,     false, makeAdaptiveUnit},
    {Method::Reference,        "reference",         N, false, false,  false, true,  No,     false, makeReferenceUnit},
};
constexpr size_t kMethodCount = std::size(kMethodTable);

namespace {
constexpr bool inMethodOrder() {
  for (size_t i = 0; i < kMethodCount; ++i)
    if (static_cast<size_t>(kMethodTable[i].method) != i) return false;
  return true;
}
static_assert(inMethodOrder(), "one row per Method, in its order");
}  // namespace

Method parseMethod(const std::string& s) {
  for (const MethodTraits& t : kMethodTable)
    if (s == t.name) return t.method;
  std::string choices;
  for (size_t i = 0; i < kMethodCount; ++i)
    choices += (i == 0 ? "" : i + 1 == kMethodCount ? " or " : ", ") + std::string(kMethodTable[i].name);
  throw std::invalid_argument(fmt::format("unknown method '{}' (expected {})", s, choices));
}

const char* toString(Method m) {
  for (const MethodTraits& t : kMethodTable)
    if (t.method == m) return t.name;
  return "?";
}

std::vector<Method> allMethods() {
  std::vector<Method> v;
  for (const MethodTraits& t : kMethodTable) v.push_back(t.method);
  return v;
}

std::string twoThreadMethods() {
  std::string s;
  for (const MethodTraits& t : kMethodTable)
    if (t.two_threads != TwoThreads::No) s += (s.empty() ? "" : ", ") + std::string(t.name);
  return s;
}

}  // namespace shd
