// Generator triangles (raster/trigen.h) through triangle setup (raster/setup.h): the stream of
// span-unit descriptors the co-simulation, the benchmarks and the cycle report feed.
#pragma once

#include <array>
#include <cstdint>

#include "raster/setup.h"
#include "raster/trigen.h"

namespace shd {

std::array<SetupVertex, 3> toSetupVertices(const GenTriangle& t, int num_attr);

class DescriptorStream {
 public:
  DescriptorStream(uint64_t seed, uint64_t count, RasterConfig cfg, TriGenOptions gen = {});
  // The next descriptor; false after `count` generator triangles. Triangles setup drops
  // (zero area, no pixel centre in the viewport) are counted and skipped.
  bool next(SpanDesc& d);
  uint64_t generated() const { return generated_; }
  uint64_t dropped() const { return dropped_; }
  const GenTriangle& last() const { return last_; }

 private:
  RasterConfig cfg_;
  TriangleGenerator gen_;
  uint64_t count_, generated_ = 0, dropped_ = 0;
  GenTriangle last_{};
};

}  // namespace shd
