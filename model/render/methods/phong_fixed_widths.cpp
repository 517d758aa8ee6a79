// phong-fixed at runtime widths (RenderOptions::phong_widths): the fixed-point datapath of
// render/fixed_widths.h, fragment by fragment as the span unit's walk produces them (the
// squared norm by the recurrence before the z-test, as the hardware runs it on every fragment,
// then the z-test, the datapath and the write). Device requests as in phong_fixed.cpp's
// fragment path: answered by the unit's memo, or batched per triangle for the RTL.
// phong_fixed.cpp's makePhongFixedUnit makes this unit when the options hold widths; without
// them nothing here runs.
#include <cmath>
#include <memory>
#include <optional>

#include "render/draw.h"
#include "render/fixed_widths.h"

namespace shd {

namespace {

class PhongWidthsUnit final : public MethodUnit {
 public:
  explicit PhongWidthsUnit(Frame& f) : MethodUnit(Method::PhongFixed), f_(f), widths_(*f.opt.phong_widths) {}

  void beginObject() override {
    const ObjectShading& o = f_.obj;
    shader_.emplace(f_.ctx, *o.material, o.lobe, &o.coding, o.spec != nullptr ? o.spec->memo() : nullptr, widths_);
  }

  void draw(const SpanTriangle& tri) override {
    req_.begin();
    const PixelWriter write = f_.writer(tri.tag);
    const bool batched = f_.batchesRequests(Method::PhongFixed);
    SquaredNorms squared_norm(tri);
    FixedWidthsShader& sh = *shader_;
    auto fragment = [&](int32_t x, int32_t y, const int64_t* attr) {
      const uint64_t sqnorm = squared_norm(x, y, attr);
      const size_t p = static_cast<size_t>(y) * static_cast<size_t>(f_.W) + static_cast<size_t>(x);
      const int64_t wcode = attr[3];
      if (wcode <= f_.fb.depth[p]) {
        ++f_.st.depth_rejected;
        return;
      }
      const Vec3 pc = sh.needsPosition() ? f_.proj.pixelCam(x, y, static_cast<double>(wcode) * kUnitLsb) : Vec3{};
      const size_t first = req_.requests.size();
      const FixedShade fs = sh.shade(attr, sqnorm, pc, &req_.requests);
      req_.zero_requests += fs.device_zero;
      if (batched) {
        req_.pending.push_back({p, wcode, {sh.lsb(fs.code[0]), sh.lsb(fs.code[1]), sh.lsb(fs.code[2])}, first,
                                req_.requests.size() - first});
        return;
      }
      req_.memo_requests += fs.device_requests;
      f_.st.pixels_covered += write(p, wcode, sh.colour(fs));
    };
    f_.walk(tri, fragment);
    req_.finish(f_, write);
  }

 private:
  Frame& f_;
  const PhongWidths widths_;
  std::optional<FixedWidthsShader> shader_;  // the object's
  PixelRequests req_;
};

}  // namespace

std::unique_ptr<MethodUnit> makePhongWidthsUnit(Frame& f) { return std::make_unique<PhongWidthsUnit>(f); }

}  // namespace shd
