// Helpers shared by the test suites.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "config/registry.h"
#include "render/render.h"
#include "scene/sphere.h"

namespace shd::testutil {

// The outward face normal of a triangle in idx3d's vertex order (sphere.h: (c - a) x (b - a)).
inline Vec3 outwardFaceNormal(const Mesh& m, const std::array<uint32_t, 3>& t) {
  const Vec3 a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
  return cross(c - a, b - a);
}

inline Vec3 centroid(const Mesh& m, const std::array<uint32_t, 3>& t) {
  return (1.0 / 3.0) * (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]]);
}

// The registry's span configurations (the lane modes, as the paper's and as the full-rate unit),
// one's parameters, and the paper's units alone (RowAhead 0).
inline std::vector<std::string> spanModes() { return builtinConfigNames("span"); }
inline SpanParams spanParams(const std::string& mode) { return spanConfig(mode).rtl; }
inline std::vector<std::string> paperSpanModes() {
  std::vector<std::string> out;
  for (const std::string& m : spanModes())
    if (spanParams(m).RowAhead == 0) out.push_back(m);
  return out;
}

// A fresh, empty directory for the running test: <TempDir>/<area>/<Suite.Test> ('/' of
// parameterised names replaced). ctest runs the tests of a file as parallel processes, so each
// test keeps its files apart.
inline std::filesystem::path freshTestDir(const std::string& area) {
  const testing::TestInfo* t = testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string(t->test_suite_name()) + "." + t->name();
  std::replace(name.begin(), name.end(), '/', '_');
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / area / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// The names in a directory, sorted.
inline std::vector<std::string> dirEntries(const std::filesystem::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

// The message of the exception of type E that f() throws, or "" if it throws none.
template <class E = std::exception, class F>
std::string errorOf(F f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "";
}

// A specular engine that only forwards evaluate(): no model for the memo, so a renderer sends
// every request in batches, as to the RTL.
class BatchOnly final : public SpecEngine {
 public:
  explicit BatchOnly(SpecEngine& e) : e_(e) {}
  const PromTable& table() const override { return e_.table(); }
  uint64_t evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) override {
    return e_.evaluate(in, out);
  }

 private:
  SpecEngine& e_;
};

}  // namespace shd::testutil
