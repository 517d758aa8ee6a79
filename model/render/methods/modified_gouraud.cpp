// modified-gouraud: paper 4.4 as corrected (docs/paper-corrections.md, 4.4). On each edge the
// point where N(t).H peaks, t1 = (cos chi cos psi - cos alpha) / ((cos psi - 1)(cos alpha +
// cos chi)), a maximum only when cos alpha + cos chi > 0 and t1 in (0, 1) (equal or opposite
// normals: no interior maximum). Where the exactly shaded colour there exceeds the Gouraud
// colour by more than modified_threshold_lsb, the point becomes a vertex: 1, 2 or 3 such points
// split the triangle into 2, 3 or 4 parts (Fig. 13), each drawn by the gouraud unit.
// RenderStats::split_parts counts the parts of the triangles split.
#include <stdexcept>

#include "render/draw.h"

namespace shd {

double edgeMaximumT(Vec3 na, Vec3 nb, Vec3 h) {
  const double cchi = dot(na, h), calpha = dot(nb, h), cpsi = dot(na, nb);
  if (1 - cpsi < 1e-12) return -1;    // equal normals: the cosine is constant along the edge
  if (1 + cpsi < 1e-12) return -1;    // opposite normals: N(t) vanishes at t = 1/2
  if (calpha + cchi <= 0) return -1;  // the root is a minimum (or none): the maximum is an end
  const double t = (cchi * cpsi - calpha) / ((cpsi - 1) * (calpha + cchi));
  return t > 0 && t < 1 ? t : -1;
}

namespace {

using Tri = std::array<PVertex, 3>;

class ModifiedGouraudUnit final : public MethodUnit {
 public:
  explicit ModifiedGouraudUnit(Frame& f)
      : MethodUnit(Method::ModifiedGouraud), f_(f), gouraud_(f.unit(Method::Gouraud)) {}

  void parts(const Fan& fan, Parts& out) override {
    splits_.clear();
    splits_.reserve(4 * fan.size());  // at most 4 parts per fan triangle: no reallocation below
    for (size_t k = 1; k + 1 < fan.size(); ++k) {
      const size_t first = splits_.size();
      split({*fan[0], *fan[k], *fan[k + 1]});
      if (splits_.size() - first > 1) f_.st.split_parts += splits_.size() - first;
      for (size_t i = first; i < splits_.size(); ++i)
        addPart(out, &splits_[i][0], &splits_[i][1], &splits_[i][2], &gouraud_, Method::Gouraud);
    }
  }
  void draw(const SpanTriangle&) override {
    throw std::logic_error("render: modified-gouraud's parts are drawn by the gouraud unit");
  }

 private:
  // The triangle's parts appended to splits_: t itself, or t split at its edges' maxima.
  void split(const Tri& t);
  // Edge e's split point (t[e]..t[e + 1]) into *pt, if one gains more than the threshold.
  bool edgePoint(const PVertex& a, const PVertex& b, PVertex* pt);

  Frame& f_;
  MethodUnit& gouraud_;
  std::vector<Tri> splits_;  // the polygon's parts
};

bool ModifiedGouraudUnit::edgePoint(const PVertex& a, const PVertex& b, PVertex* pt) {
  double best_gain = f_.opt.modified_threshold_lsb;
  bool has = false;
  for (const CameraLight& l : f_.ctx.lights) {
    const Vec3 mid = 0.5 * (a.cam + b.cam);
    const Vec3 h = normalize(lightDirection(l, mid) + f_.ctx.view);
    const double tm = edgeMaximumT(normalize(a.n), normalize(b.n), h);
    if (tm < 0) continue;
    PVertex v = lerp(a, b, tm);
    v.cam = f_.proj.vertexCam(v);
    v.n = normalize(v.n);
    v.colour = f_.shadeNow(v.n, v.cam);
    double gain = 0;
    for (size_t k = 0; k < 3; ++k) gain = std::max(gain, v.colour[k] - (a.colour[k] + tm * (b.colour[k] - a.colour[k])));
    if (gain > best_gain) {
      best_gain = gain;
      *pt = v;
      has = true;
    }
  }
  return has;
}

void ModifiedGouraudUnit::split(const Tri& t) {
  std::array<bool, 3> has{};
  Tri pt;
  for (size_t e = 0; e < 3; ++e) has[e] = edgePoint(t[e], t[(e + 1) % 3], &pt[e]);
  const int count = has[0] + has[1] + has[2];
  if (count == 0) {
    splits_.push_back(t);
    return;
  }
  if (count == 3) {
    splits_.insert(splits_.end(), {Tri{t[0], pt[0], pt[2]}, Tri{pt[0], t[1], pt[1]}, Tri{pt[2], pt[1], t[2]},
                                   Tri{pt[0], pt[1], pt[2]}});
    return;
  }
  // Rotate so that the split edges come first: edge 0 (and edge 1 for two points).
  size_t r = 0;
  if (count == 1) r = has[0] ? 0 : (has[1] ? 1 : 2);
  else r = !has[2] ? 0 : (!has[0] ? 1 : 2);  // the unsplit edge becomes edge 2
  const PVertex &v0 = t[r], &v1 = t[(r + 1) % 3], &v2 = t[(r + 2) % 3];
  const PVertex& P = pt[r];
  if (count == 1) {
    splits_.insert(splits_.end(), {Tri{v0, P, v2}, Tri{P, v1, v2}});
    return;
  }
  const PVertex& Q = pt[(r + 1) % 3];
  splits_.insert(splits_.end(), {Tri{P, v1, Q}, Tri{v0, P, Q}, Tri{v0, Q, v2}});
}

}  // namespace

std::unique_ptr<MethodUnit> makeModifiedGouraudUnit(Frame& f) { return std::make_unique<ModifiedGouraudUnit>(f); }

}  // namespace shd
