#include "raster/desc_stream.h"

namespace shd {

std::array<SetupVertex, 3> toSetupVertices(const GenTriangle& t, int num_attr) {
  std::array<SetupVertex, 3> v;
  for (size_t i = 0; i < 3; ++i) {
    v[i].x = t.v[i].x;
    v[i].y = t.v[i].y;
    v[i].attr.assign(t.v[i].attr.begin(), t.v[i].attr.begin() + num_attr);
  }
  return v;
}

DescriptorStream::DescriptorStream(uint64_t seed, uint64_t count, RasterConfig cfg, TriGenOptions gen)
    : cfg_(std::move(cfg)), gen_(seed, [&] {
        gen.width = cfg_.width;
        gen.height = cfg_.height;
        gen.subpixel_bits = cfg_.subpixel_bits;
        gen.num_attr = cfg_.unit.NumAttr;
        return gen;
      }()),
      count_(count) {}

bool DescriptorStream::next(SpanDesc& d) {
  while (generated_ < count_) {
    last_ = gen_.next();
    ++generated_;
    SetupResult s = setupTriangle(toSetupVertices(last_, cfg_.unit.NumAttr), last_.id, cfg_);
    if (s.desc) {
      d = std::move(*s.desc);
      return true;
    }
    ++dropped_;
  }
  return false;
}

}  // namespace shd
