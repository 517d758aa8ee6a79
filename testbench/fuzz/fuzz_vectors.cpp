// libFuzzer target: the vector-file readers (sim/vectors/vector_file.h vectorFileUnit,
// loadSpecVectors, loadSpanVectors). Input: the file's bytes, read by all three whatever its
// "# unit" line says. Clean rejection: std::runtime_error (documented for all three).
// Property of an accepted file: written back (render*Vectors) it is read again, and writing
// that gives the same text (the writer's output is a fixed point of read-then-write). The
// writer refusing what the reader accepted (std::invalid_argument) is a finding too.
#include <stdexcept>
#include <string>

#include "fuzz_util.h"
#include "vectors/vector_file.h"

namespace {

using shd::fuzz::finding;

// read -> write -> read -> write: the two texts written must be equal.
template <class Vectors, class Load, class Render>
void checkFixedPoint(const char* unit, const std::string& path, Load load, Render render) {
  Vectors v;
  try {
    v = load(path);
  } catch (const std::runtime_error& e) {
    shd::fuzz::rejected(e);
    return;
  }
  std::string first;
  try {
    first = render(v);
  } catch (const std::invalid_argument& e) {
    finding(std::string(unit) + ": the writer refuses what the reader accepted: " + e.what());
  }
  const std::string again =
      shd::fuzz::writeInput("again.vec", reinterpret_cast<const uint8_t*>(first.data()), first.size());
  Vectors w;
  try {
    w = load(again);
  } catch (const std::runtime_error& e) {
    finding(std::string(unit) + ": the reader refuses what the writer wrote: " + e.what());
  }
  if (render(w) != first) finding(std::string(unit) + ": read -> write is not a fixed point");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = shd::fuzz::writeInput("input.vec", data, size);
  try {
    shd::vectorFileUnit(path);
  } catch (const std::runtime_error&) {
  }
  checkFixedPoint<shd::SpecVectors>("spec", path, shd::loadSpecVectors, shd::renderSpecVectors);
  checkFixedPoint<shd::SpanVectors>("span", path, shd::loadSpanVectors, shd::renderSpanVectors);
  return 0;
}
