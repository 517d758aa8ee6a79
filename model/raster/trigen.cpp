#include "raster/trigen.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "scene/vec.h"  // kPi

namespace shd {

namespace {

// Random numbers from the raw 64-bit stream, so that a seed gives the same triangles with every
// standard library (the std:: distributions are implementation-defined).
double u01(std::mt19937_64& g) { return static_cast<double>(g() >> 11) * 0x1.0p-53; }
double uniform(std::mt19937_64& g, double lo, double hi) { return lo + (hi - lo) * u01(g); }
double logUniform(std::mt19937_64& g, double lo, double hi) {
  return lo * std::exp(u01(g) * std::log(hi / lo));
}
bool chance(std::mt19937_64& g, double p) { return u01(g) < p; }
int below(std::mt19937_64& g, int n) {  // 0 .. n-1 (bias < 2^-32, irrelevant here)
  return static_cast<int>(((g() >> 32) * static_cast<uint64_t>(n)) >> 32);
}
template <size_t N>
int pickWeighted(std::mt19937_64& g, const std::array<double, N>& w, double total) {
  double u = u01(g) * total;
  for (size_t i = 0; i < N; ++i) {
    if (u < w[i]) return static_cast<int>(i);
    u -= w[i];
  }
  for (size_t i = N; i-- > 0;)  // rounding left u at the very top: the last non-zero weight
    if (w[i] > 0) return static_cast<int>(i);
  return 0;
}

struct P2 {
  double x, y;
};
using Tri = std::array<P2, 3>;

double area2Of(const Tri& t) {
  return (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y);
}
double areaOf(const Tri& t) { return 0.5 * std::fabs(area2Of(t)); }

void translate(Tri& t, double dx, double dy) {
  for (P2& p : t) {
    p.x += dx;
    p.y += dy;
  }
}

// Moves the centroid to the origin.
void centre(Tri& t) {
  translate(t, -(t[0].x + t[1].x + t[2].x) / 3, -(t[0].y + t[1].y + t[2].y) / 3);
}

Box bboxOf(const Tri& t) {
  Box b{t[0].x, t[0].y, t[0].x, t[0].y};
  for (const P2& p : t) {
    b.x0 = std::min(b.x0, p.x);
    b.y0 = std::min(b.y0, p.y);
    b.x1 = std::max(b.x1, p.x);
    b.y1 = std::max(b.y1, p.y);
  }
  return b;
}

bool inside(const Box& b, const Box& box) {
  return b.x0 >= box.x0 && b.y0 >= box.y0 && b.x1 <= box.x1 && b.y1 <= box.y1;
}

// Shift along one axis so that [lo, hi] lies in [blo, bhi] (if it can).
double fitShift(double lo, double hi, double blo, double bhi) {
  if (lo < blo) return blo - lo;
  if (hi > bhi) return bhi - hi;
  return 0.0;
}

// Snapping of one coordinate.
double toPixelCentre(double v) { return std::floor(v) + 0.5; }
double toPixelCorner(double v) { return std::round(v); }
double toSubpixel(double v, double scale) { return std::round(v * scale) / scale; }
double toHalfSubpixel(double v, double scale) { return (std::floor(v * scale) + 0.5) / scale; }

// A triangle of the given area with quality 4 sqrt(3) A / sum(l^2) >= 0.35, centroid at 0.
Tri regularShape(std::mt19937_64& g, double area) {
  const double kMinQuality = 0.35;
  for (;;) {
    Tri t{{{u01(g), u01(g)}, {u01(g), u01(g)}, {u01(g), u01(g)}}};
    const double a = areaOf(t);
    double l2 = 0;
    for (int k = 0; k < 3; ++k) {
      const P2 p = t[static_cast<size_t>(k)], q = t[static_cast<size_t>((k + 1) % 3)];
      l2 += (p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y);
    }
    if (!(4 * std::sqrt(3.0) * a >= kMinQuality * l2)) continue;
    centre(t);
    const double s = std::sqrt(area / a);
    for (P2& p : t) {
      p.x *= s;
      p.y *= s;
    }
    return t;
  }
}

// A sliver: long edge L along u, third vertex at height w over it (local (u, v) frame), then
// oriented. Aspect L / w log-uniform in [10, 1e4], L capped at max_len.
Tri sliverShape(std::mt19937_64& g, double area, double max_len) {
  const double aspect = logUniform(g, 10.0, 1e4);
  double len = std::sqrt(2 * area * aspect);
  if (len > max_len) len = max_len;
  const double h = 2 * area / len;
  const double t = u01(g);  // foot of the apex along the long edge
  std::array<P2, 3> uv{{{0, 0}, {len, 0}, {t * len, h}}};
  if (chance(g, 0.5)) uv[2].y = -h;
  const double r = u01(g);
  Tri out;
  if (r < 0.8) {
    double ang;
    if (r < 0.5) {
      ang = uniform(g, 0, 2 * kPi);
    } else {
      const double eps = logUniform(g, 1e-6, 1e-2) * (chance(g, 0.5) ? 1 : -1);
      const double base = (r < 0.65 ? 0.0 : 0.5 * kPi) + (chance(g, 0.5) ? kPi : 0.0);
      ang = base + eps;
    }
    const double c = std::cos(ang), s = std::sin(ang);
    for (size_t k = 0; k < 3; ++k) out[k] = {c * uv[k].x - s * uv[k].y, s * uv[k].x + c * uv[k].y};
  } else {
    // Exactly axis-aligned long edge: swap / negate coordinates, no rounding.
    const bool vertical = r >= 0.9;
    const double sx = chance(g, 0.5) ? 1 : -1, sy = chance(g, 0.5) ? 1 : -1;
    for (size_t k = 0; k < 3; ++k)
      out[k] = vertical ? P2{sx * uv[k].y, sy * uv[k].x} : P2{sx * uv[k].x, sy * uv[k].y};
  }
  centre(out);
  return out;
}

}  // namespace

const char* toString(SizeClass c) {
  switch (c) {
    case SizeClass::Pixel1: return "pixel1";
    case SizeClass::Small: return "small";
    case SizeClass::Mesh: return "mesh";
    case SizeClass::Large: return "large";
    case SizeClass::Screen: return "screen";
  }
  return "?";
}

const char* toString(TriShape s) {
  switch (s) {
    case TriShape::Regular: return "regular";
    case TriShape::Sliver: return "sliver";
    case TriShape::CutPoint: return "cutpoint";
    case TriShape::ZeroArea: return "zeroarea";
    case TriShape::OffScreen: return "offscreen";
    case TriShape::Snapped: return "snapped";
    case TriShape::MeshGrid: return "meshgrid";
    case TriShape::MeshFan: return "meshfan";
  }
  return "?";
}

std::string GenTriangle::kind() const {
  return std::string(toString(size)) + "/" + toString(shape);
}

AreaRange areaRange(SizeClass c, const TriGenOptions& opt) {
  const double wh = static_cast<double>(opt.width) * opt.height;
  switch (c) {
    case SizeClass::Pixel1: return {0.5, 2};
    case SizeClass::Small: return {2, 10};
    case SizeClass::Mesh: return {10, 100};
    case SizeClass::Large: return {100, 1e4};
    case SizeClass::Screen: return {wh / 2, 2 * wh};
  }
  return {0, 0};
}

SizeClass classifyArea(double area, const TriGenOptions& opt) {
  if (area < 2) return SizeClass::Pixel1;
  if (area < 10) return SizeClass::Small;
  if (area < 100) return SizeClass::Mesh;
  if (area < 0.5 * opt.width * opt.height) return SizeClass::Large;
  return SizeClass::Screen;
}

Box guardBox(const TriGenOptions& opt) {
  const double g = opt.guard_band;
  return {std::max(-g, -kTriGenMaxCoord), std::max(-g, -kTriGenMaxCoord),
          std::min(opt.width + g, kTriGenMaxCoord), std::min(opt.height + g, kTriGenMaxCoord)};
}

double signedArea2(const GenTriangle& t) {
  return (t.v[1].x - t.v[0].x) * (t.v[2].y - t.v[0].y) -
         (t.v[2].x - t.v[0].x) * (t.v[1].y - t.v[0].y);
}

namespace {

double sumOf(const double* w, int n) {
  double s = 0;
  for (int i = 0; i < n; ++i) {
    if (!(w[i] >= 0)) throw std::invalid_argument("trigen: weights must be >= 0");
    s += w[i];
  }
  if (!(s > 0)) throw std::invalid_argument("trigen: weights must not all be 0");
  return s;
}

void checkOptions(const TriGenOptions& opt) {
  if (opt.width < 1 || opt.height < 1) throw std::invalid_argument("trigen: empty viewport");
  if (opt.width > kTriGenMaxCoord || opt.height > kTriGenMaxCoord)
    throw std::invalid_argument("trigen: viewport beyond +-8192 px");
  if (opt.num_attr < 0 || opt.num_attr > kTriGenMaxAttr)
    throw std::invalid_argument("trigen: num_attr out of range");
  if (opt.subpixel_bits < 0 || opt.subpixel_bits > 20)
    throw std::invalid_argument("trigen: subpixel_bits out of range");
  if (!(opt.guard_band >= 0)) throw std::invalid_argument("trigen: guard_band < 0");
  sumOf(opt.size_weight.data(), kNumSizeClasses);
  sumOf(opt.shape_weight.data(), kNumStreamShapes);
}

// Vertex attributes: uniform, 10 % exactly on a range end. One draw per value: its top 53 bits
// give the uniform value, its low 11 bits (which u01 drops) the end choice (205/2048 ~ 10 %).
void randomAttrs(std::mt19937_64& g, const TriGenOptions& opt, GenVertex& v) {
  for (int k = 0; k < opt.num_attr; ++k) {
    const AttrRange r = opt.attr_range[static_cast<size_t>(k)];
    const uint64_t bits = g();
    const uint64_t low = bits & 0x7ff;
    v.attr[static_cast<size_t>(k)] =
        low < 205 ? ((low & 1) ? r.hi : r.lo)
                  : r.lo + (r.hi - r.lo) * (static_cast<double>(bits >> 11) * 0x1.0p-53);
  }
}

class StreamBuilder {
 public:
  StreamBuilder(std::mt19937_64& g, const TriGenOptions& opt)
      : g_(g), opt_(opt), guard_(guardBox(opt)), view_{0, 0, double(opt.width), double(opt.height)},
        scale_(std::ldexp(1.0, opt.subpixel_bits)) {}

  Tri make(SizeClass sc, TriShape sh) {
    const AreaRange range = areaRange(sc, opt_);
    switch (sh) {
      case TriShape::ZeroArea: return zeroArea(sc, range);
      case TriShape::CutPoint:
      case TriShape::Snapped: return snapped(sc, sh, range);
      default: break;
    }
    for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
      const double area = logUniform(g_, range.lo, range.hi);
      Tri t = sh == TriShape::Sliver ? sliverShape(g_, area, maxLen()) : regularShape(g_, area);
      if (place(t, sc, sh == TriShape::OffScreen)) return t;
    }
    giveUp(sc, sh);
  }

 private:
  static constexpr int kMaxAttempts = 256;

  [[noreturn]] void giveUp(SizeClass sc, TriShape sh) const {
    throw std::runtime_error(std::string("trigen: cannot fit a ") + toString(sc) + "/" +
                             toString(sh) + " triangle in the guard box; raise guard_band");
  }

  // Longest sliver edge. A vertex lies at most 2/3 of it from the centroid, which is in the
  // viewport, so it stays within the guard band (and +-kTriGenMaxCoord); half the viewport
  // at least, or large slivers in a narrow guard band could not exist (placement shifts those).
  double maxLen() const {
    const double reach = std::min(opt_.guard_band, kTriGenMaxCoord - std::max(view_.x1, view_.y1));
    return std::max(reach, 0.5 * std::min(view_.x1, view_.y1));
  }

  // Moves an origin-centred triangle to its place; false if it cannot fit the guard box.
  bool place(Tri& t, SizeClass sc, bool offscreen) {
    const Box b = bboxOf(t);
    const double w = view_.x1, h = view_.y1;
    double cx, cy;
    if (offscreen) {
      if (chance(g_, 0.75)) {  // on an edge: left, right, top, bottom
        const int e = below(g_, 4);
        const double along = u01(g_);
        cx = e == 0 ? 0 : e == 1 ? w : along * w;
        cy = e == 2 ? 0 : e == 3 ? h : along * h;
      } else {
        const int c = below(g_, 4);
        cx = (c & 1) ? w : 0;
        cy = (c & 2) ? h : 0;
      }
    } else if (sc == SizeClass::Screen) {
      cx = uniform(g_, 0.25 * w, 0.75 * w);
      cy = uniform(g_, 0.25 * h, 0.75 * h);
    } else if (b.x1 - b.x0 <= w && b.y1 - b.y0 <= h) {
      cx = uniform(g_, -b.x0, w - b.x1);  // bbox inside the viewport
      cy = uniform(g_, -b.y0, h - b.y1);
    } else {
      cx = uniform(g_, 0, w);
      cy = uniform(g_, 0, h);
    }
    translate(t, cx, cy);
    Box p = bboxOf(t);
    translate(t, fitShift(p.x0, p.x1, guard_.x0, guard_.x1), fitShift(p.y0, p.y1, guard_.y0, guard_.y1));
    return inside(bboxOf(t), guard_);
  }

  // Cut points (both lattices) and snapped vertices; retried until the area is in the class.
  Tri snapped(SizeClass sc, TriShape sh, AreaRange range) {
    for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
      const double area = logUniform(g_, range.lo, range.hi);
      Tri t = regularShape(g_, area);
      if (!place(t, sc, false)) continue;
      if (sh == TriShape::CutPoint) {
        const double off = chance(g_, 0.5) ? 0.5 : 0.0;  // pixel centres or pixel corners
        for (P2& p : t) {
          p.x = std::floor(p.x) + off;
          p.y = std::floor(p.y) + off;
        }
      } else {
        for (P2& p : t) snapVertex(p);
      }
      const double a = areaOf(t);
      if (a >= range.lo && a <= range.hi && inside(bboxOf(t), guard_)) return t;
    }
    giveUp(sc, sh);
  }

  void snapVertex(P2& p) {
    auto snap1 = [&](double v, int mode) {
      switch (mode) {
        case 0: return toPixelCentre(v);
        case 1: return toSubpixel(v, scale_);
        default: return toHalfSubpixel(v, scale_);
      }
    };
    const int mode = below(g_, 4);  // 3: each coordinate its own mode
    if (mode < 3) {
      p.x = snap1(p.x, mode);
      p.y = snap1(p.y, mode);
    } else {
      p.x = snap1(p.x, below(g_, 3));
      p.y = snap1(p.y, below(g_, 3));
    }
  }

  // Exactly zero area at the length scale of the class.
  Tri zeroArea(SizeClass sc, AreaRange range) {
    const double len = std::min(std::sqrt(2 * logUniform(g_, range.lo, range.hi)), maxLen());
    const double r = u01(g_);
    if (r < 0.4) {  // two equal vertices
      for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
        Tri t = regularShape(g_, 0.5 * len * len);
        if (!place(t, sc, false)) continue;
        const int k = below(g_, 3), m = (k + 1 + below(g_, 2)) % 3;
        t[static_cast<size_t>(k)] = t[static_cast<size_t>(m)];
        return t;
      }
      giveUp(sc, TriShape::ZeroArea);
    }
    if (r < 0.5) {  // a point
      const P2 p{uniform(g_, 0, view_.x1), uniform(g_, 0, view_.y1)};
      return Tri{{p, p, p}};
    }
    // Collinear: p0 + t_k d on the subpixel lattice, d = (dx, dy) / 2^s with small integers and
    // integer t_k, so every coordinate and every product in the orientation test is exact.
    int dx, dy;
    if (chance(g_, 0.2)) {
      dx = chance(g_, 0.5) ? 1 + below(g_, 16) : 0;
      dy = dx == 0 ? 1 + below(g_, 16) : 0;
    } else {
      do {
        dx = below(g_, 33) - 16;
        dy = below(g_, 33) - 16;
      } while (dx == 0 || dy == 0);
    }
    const double step = std::hypot(dx, dy) / scale_;  // length of d, px
    const int tmax = std::max(2, static_cast<int>(len / step));
    std::array<int, 3> tk{0, tmax, 1 + below(g_, tmax - 1)};  // three distinct points
    for (int k = 2; k > 0; --k) std::swap(tk[static_cast<size_t>(k)], tk[static_cast<size_t>(below(g_, k + 1))]);
    Tri t;
    for (size_t k = 0; k < 3; ++k) t[k] = {tk[k] * dx / scale_, tk[k] * dy / scale_};
    // Place on the lattice: a translation by a multiple of 1/2^s keeps every value exact.
    const Box b = bboxOf(t);
    const double w = view_.x1, h = view_.y1;
    double cx = b.x1 - b.x0 <= w ? uniform(g_, -b.x0, w - b.x1) : uniform(g_, -0.5 * (b.x0 + b.x1), w - 0.5 * (b.x0 + b.x1));
    double cy = b.y1 - b.y0 <= h ? uniform(g_, -b.y0, h - b.y1) : uniform(g_, -0.5 * (b.y0 + b.y1), h - 0.5 * (b.y0 + b.y1));
    cx = std::floor(cx * scale_) / scale_;
    cy = std::floor(cy * scale_) / scale_;
    translate(t, cx, cy);
    const Box p = bboxOf(t);
    // Shift into the guard box by whole lattice steps, rounding away from zero.
    auto latticeShift = [&](double d) {
      return (d > 0 ? std::ceil(d * scale_) : std::floor(d * scale_)) / scale_;
    };
    translate(t, latticeShift(fitShift(p.x0, p.x1, guard_.x0, guard_.x1)),
              latticeShift(fitShift(p.y0, p.y1, guard_.y0, guard_.y1)));
    return t;
  }

  std::mt19937_64& g_;
  const TriGenOptions& opt_;
  Box guard_, view_;
  double scale_;  // 2^subpixel_bits
};

}  // namespace

TriangleGenerator::TriangleGenerator(uint64_t seed, const TriGenOptions& opt)
    : rng_(seed), opt_(opt) {
  checkOptions(opt_);
  size_total_ = sumOf(opt_.size_weight.data(), kNumSizeClasses);
  shape_total_ = sumOf(opt_.shape_weight.data(), kNumStreamShapes);
}

GenTriangle TriangleGenerator::next() {
  GenTriangle t{};
  t.size = static_cast<SizeClass>(pickWeighted(rng_, opt_.size_weight, size_total_));
  t.shape = static_cast<TriShape>(pickWeighted(rng_, opt_.shape_weight, shape_total_));
  StreamBuilder builder(rng_, opt_);
  const Tri p = builder.make(t.size, t.shape);
  for (size_t k = 0; k < 3; ++k) {
    t.v[k].x = p[k].x;
    t.v[k].y = p[k].y;
  }
  if (chance(rng_, 0.1)) {  // flat attributes
    randomAttrs(rng_, opt_, t.v[0]);
    t.v[1].attr = t.v[2].attr = t.v[0].attr;
  } else {
    for (GenVertex& v : t.v) randomAttrs(rng_, opt_, v);
  }
  if (chance(rng_, 0.5)) std::swap(t.v[1], t.v[2]);
  t.id = next_id_++;
  return t;
}

// ---------------------------------------------------------------------------------------------
// Meshes

namespace {

int meshWinding(std::mt19937_64& g, int w) {
  if (w > 0) return 1;
  if (w < 0) return -1;
  return chance(g, 0.5) ? 1 : -1;
}

// Snaps v to a pixel centre, a pixel corner or a half-subpixel point, if that keeps it within
// [lo, hi]; otherwise returns it unchanged.
double snapWithin(std::mt19937_64& g, double v, double lo, double hi, double scale) {
  const int mode = below(g, 3);
  const double s = mode == 0 ? toPixelCentre(v) : mode == 1 ? toPixelCorner(v) : toHalfSubpixel(v, scale);
  return (s >= lo && s <= hi) ? s : v;
}

GenTriangle meshTriangle(const GenVertex& a, const GenVertex& b, const GenVertex& c, int winding,
                         TriShape shape, const TriGenOptions& opt, uint32_t id) {
  GenTriangle t{};
  t.v = {a, b, c};
  if ((signedArea2(t) > 0) != (winding > 0)) std::swap(t.v[1], t.v[2]);
  t.id = id;
  t.shape = shape;
  t.size = classifyArea(0.5 * std::fabs(signedArea2(t)), opt);
  return t;
}

}  // namespace

std::vector<GenTriangle> makeSharedEdgeMesh(std::mt19937_64& g, const TriGenOptions& opt, int cols,
                                            int rows, const MeshGenOptions& mopt) {
  checkOptions(opt);
  if (cols < 1 || rows < 1) throw std::invalid_argument("makeSharedEdgeMesh: cols, rows >= 1");
  if (!(mopt.jitter >= 0 && mopt.jitter < 0.5))
    throw std::invalid_argument("makeSharedEdgeMesh: jitter must be in [0, 0.5)");
  Box r{mopt.x0, mopt.y0, mopt.x1, mopt.y1};
  if (!(r.x1 > r.x0 && r.y1 > r.y0)) r = {0, 0, double(opt.width), double(opt.height)};
  if (!inside(r, guardBox(opt)))
    throw std::invalid_argument("makeSharedEdgeMesh: region outside the guard box");
  const int winding = meshWinding(g, mopt.winding);
  const double cw = (r.x1 - r.x0) / cols, ch = (r.y1 - r.y0) / rows;
  const double scale = std::ldexp(1.0, opt.subpixel_bits);

  const size_t nx = static_cast<size_t>(cols) + 1;
  std::vector<GenVertex> vert(nx * (static_cast<size_t>(rows) + 1));
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i <= cols; ++i) {
      // Grid position; the last row and column sit exactly on the far boundary.
      const double bx = i == cols ? r.x1 : r.x0 + i * cw;
      const double by = j == rows ? r.y1 : r.y0 + j * ch;
      double x = bx, y = by;
      const bool free_x = i > 0 && i < cols, free_y = j > 0 && j < rows;
      if (free_x) {
        x += uniform(g, -1, 1) * mopt.jitter * cw;
        if (chance(g, mopt.snap_share)) x = snapWithin(g, x, bx - 0.49 * cw, bx + 0.49 * cw, scale);
      }
      if (free_y) {
        y += uniform(g, -1, 1) * mopt.jitter * ch;
        if (chance(g, mopt.snap_share)) y = snapWithin(g, y, by - 0.49 * ch, by + 0.49 * ch, scale);
      }
      GenVertex& v = vert[static_cast<size_t>(j) * nx + static_cast<size_t>(i)];
      v.x = x;
      v.y = y;
      randomAttrs(g, opt, v);
    }

  std::vector<GenTriangle> out;
  out.reserve(2 * static_cast<size_t>(cols) * static_cast<size_t>(rows));
  uint32_t id = mopt.first_id;
  auto tri2 = [](const GenVertex& a, const GenVertex& b, const GenVertex& c) {
    return (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
  };
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) {
      // Quad a b c d: top-left, top-right, bottom-right, bottom-left (clockwise on screen).
      const size_t ia = static_cast<size_t>(j) * nx + static_cast<size_t>(i);
      const GenVertex &a = vert[ia], &b = vert[ia + 1], &c = vert[ia + nx + 1], &d = vert[ia + nx];
      const bool diag_ac_ok = tri2(a, b, c) > 0 && tri2(a, c, d) > 0;
      const bool diag_bd_ok = tri2(a, b, d) > 0 && tri2(b, c, d) > 0;
      bool use_ac = chance(g, 0.5);
      if (use_ac && !diag_ac_ok) use_ac = false;
      if (!use_ac && !diag_bd_ok) use_ac = true;
      if (!(use_ac ? diag_ac_ok : diag_bd_ok))
        throw std::logic_error("makeSharedEdgeMesh: a cell has no valid diagonal");  // cannot happen for a simple quad
      if (use_ac) {
        out.push_back(meshTriangle(a, b, c, winding, TriShape::MeshGrid, opt, id++));
        out.push_back(meshTriangle(a, c, d, winding, TriShape::MeshGrid, opt, id++));
      } else {
        out.push_back(meshTriangle(a, b, d, winding, TriShape::MeshGrid, opt, id++));
        out.push_back(meshTriangle(b, c, d, winding, TriShape::MeshGrid, opt, id++));
      }
    }
  return out;
}

std::vector<GenTriangle> makeFanMesh(std::mt19937_64& g, const TriGenOptions& opt, double cx,
                                     double cy, double radius, int segments,
                                     const MeshGenOptions& mopt) {
  checkOptions(opt);
  if (segments < 3) throw std::invalid_argument("makeFanMesh: segments >= 3");
  if (!(radius > 0)) throw std::invalid_argument("makeFanMesh: radius > 0");
  if (!(mopt.jitter >= 0 && mopt.jitter < 0.5))
    throw std::invalid_argument("makeFanMesh: jitter must be in [0, 0.5)");
  if (!inside(Box{cx - radius - 1, cy - radius - 1, cx + radius + 1, cy + radius + 1}, guardBox(opt)))
    throw std::invalid_argument("makeFanMesh: fan outside the guard box");
  const int winding = meshWinding(g, mopt.winding);
  const double scale = std::ldexp(1.0, opt.subpixel_bits);
  const double step = 2 * kPi / segments;

  // Ring angles phase + (k + e_k) step with |e_k| <= jitter; every angular gap must stay below
  // pi, i.e. step (1 + 2 jitter) < pi, which only binds for 3 segments.
  const double jitter = std::min(mopt.jitter, 0.45 * (kPi / step - 1));
  GenVertex centre_v{};
  centre_v.x = cx;
  centre_v.y = cy;
  randomAttrs(g, opt, centre_v);
  const double phase = uniform(g, 0, step);
  std::vector<GenVertex> ring(static_cast<size_t>(segments));
  for (int k = 0; k < segments; ++k) {
    const double ang = phase + (k + uniform(g, -1, 1) * jitter) * step;
    const double rad = radius * uniform(g, 0.5, 1.0);
    GenVertex& v = ring[static_cast<size_t>(k)];
    v.x = cx + rad * std::cos(ang);
    v.y = cy + rad * std::sin(ang);
    randomAttrs(g, opt, v);
  }
  // Angles increase clockwise on screen (y down): (centre, ring k, ring k+1) has
  // signedArea2 > 0. Snapping may not fold a triangle, so a snap is kept only if the triangles
  // it touches stay positive (with their other vertices as they are at that moment).
  auto fanArea2 = [&](int k) {
    const GenVertex &a = centre_v, &b = ring[static_cast<size_t>(k)],
                    &c = ring[static_cast<size_t>((k + 1) % segments)];
    return (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
  };
  for (int k = 0; k < segments; ++k)
    if (!(fanArea2(k) > 0))
      throw std::invalid_argument("makeFanMesh: radius too small for the segment count");
  auto trySnap = [&](GenVertex& v, auto&& still_valid) {
    if (!chance(g, mopt.snap_share)) return;
    const GenVertex keep = v;
    v.x = snapWithin(g, v.x, v.x - 1, v.x + 1, scale);
    v.y = snapWithin(g, v.y, v.y - 1, v.y + 1, scale);
    if (!still_valid()) v = keep;
  };
  trySnap(centre_v, [&] {
    for (int k = 0; k < segments; ++k)
      if (!(fanArea2(k) > 0)) return false;
    return true;
  });
  for (int k = 0; k < segments; ++k)
    trySnap(ring[static_cast<size_t>(k)],
            [&] { return fanArea2(k) > 0 && fanArea2((k + segments - 1) % segments) > 0; });
  std::vector<GenTriangle> out;
  out.reserve(static_cast<size_t>(segments));
  uint32_t id = mopt.first_id;
  for (int k = 0; k < segments; ++k)
    out.push_back(meshTriangle(centre_v, ring[static_cast<size_t>(k)],
                               ring[static_cast<size_t>((k + 1) % segments)], winding,
                               TriShape::MeshFan, opt, id++));
  return out;
}

}  // namespace shd
