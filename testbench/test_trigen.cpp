// Seeded random screen triangles (raster/trigen.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>

#include "raster/trigen.h"

namespace shd {
namespace {

constexpr uint64_t kSeed = 1;
constexpr int kStream = 100000;

double areaOf(const GenTriangle& t) { return 0.5 * std::fabs(signedArea2(t)); }

double longestEdge2(const GenTriangle& t) {
  double m = 0;
  for (int k = 0; k < 3; ++k) {
    const GenVertex &a = t.v[static_cast<size_t>(k)], &b = t.v[static_cast<size_t>((k + 1) % 3)];
    m = std::max(m, (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y));
  }
  return m;
}

Box bboxOf(const GenTriangle& t) {
  Box b{t.v[0].x, t.v[0].y, t.v[0].x, t.v[0].y};
  for (const auto& v : t.v) {
    b.x0 = std::min(b.x0, v.x);
    b.y0 = std::min(b.y0, v.y);
    b.x1 = std::max(b.x1, v.x);
    b.y1 = std::max(b.y1, v.y);
  }
  return b;
}

// Pixels of the viewport whose centre lies in the triangle (closed: edges count), brute force.
long coveredPixels(const GenTriangle& t, int w, int h) {
  const double a2 = signedArea2(t);
  if (a2 == 0) return 0;
  const double sgn = a2 > 0 ? 1 : -1;
  const Box b = bboxOf(t);
  const int x0 = std::max(0, static_cast<int>(std::floor(b.x0 - 0.5)));
  const int x1 = std::min(w - 1, static_cast<int>(std::ceil(b.x1)));
  const int y0 = std::max(0, static_cast<int>(std::floor(b.y0 - 0.5)));
  const int y1 = std::min(h - 1, static_cast<int>(std::ceil(b.y1)));
  long n = 0;
  for (int py = y0; py <= y1; ++py)
    for (int px = x0; px <= x1; ++px) {
      const double x = px + 0.5, y = py + 0.5;
      bool in = true;
      for (int k = 0; k < 3 && in; ++k) {
        const GenVertex &p = t.v[static_cast<size_t>(k)], &q = t.v[static_cast<size_t>((k + 1) % 3)];
        in = sgn * ((q.x - p.x) * (y - p.y) - (x - p.x) * (q.y - p.y)) >= 0;
      }
      n += in;
    }
  return n;
}

bool sameTriangle(const GenTriangle& a, const GenTriangle& b) {
  if (a.id != b.id || a.size != b.size || a.shape != b.shape) return false;
  for (size_t k = 0; k < 3; ++k) {
    if (a.v[k].x != b.v[k].x || a.v[k].y != b.v[k].y) return false;
    if (a.v[k].attr != b.v[k].attr) return false;
  }
  return true;
}

std::vector<GenTriangle> stream(uint64_t seed, int n, const TriGenOptions& opt = {}) {
  TriangleGenerator gen(seed, opt);
  std::vector<GenTriangle> out;
  out.reserve(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) out.push_back(gen.next());
  return out;
}

TEST(TriGen, DeterministicPerSeed) {
  const auto a = stream(kSeed, 20000), b = stream(kSeed, 20000), c = stream(kSeed + 1, 20000);
  for (size_t i = 0; i < a.size(); ++i)
    ASSERT_TRUE(sameTriangle(a[i], b[i])) << "seed " << kSeed << " triangle " << i << " "
                                          << a[i].kind() << " vs " << b[i].kind();
  size_t differ = 0;
  for (size_t i = 0; i < a.size(); ++i) differ += !sameTriangle(a[i], c[i]);
  EXPECT_GT(differ, a.size() * 9 / 10);
  for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i].id, i);
}

TEST(TriGen, EveryClassAndShapeOccursWithItsShare) {
  const TriGenOptions opt;
  const auto tris = stream(kSeed, kStream, opt);
  std::array<int, kNumSizeClasses> by_class{};
  std::array<int, kNumStreamShapes> by_shape{};
  for (const auto& t : tris) {
    ++by_class[static_cast<size_t>(t.size)];
    ASSERT_LT(static_cast<int>(t.shape), kNumStreamShapes);
    ++by_shape[static_cast<size_t>(t.shape)];
  }
  double wc = 0, ws = 0;
  for (double w : opt.size_weight) wc += w;
  for (double w : opt.shape_weight) ws += w;
  auto check = [&](const char* name, int count, double share) {
    const double mean = kStream * share, sigma = std::sqrt(mean * (1 - share));
    std::printf("%-10s %6d  expected %8.1f\n", name, count, mean);
    EXPECT_GT(count, 0) << name << " seed " << kSeed;
    EXPECT_NEAR(count, mean, 5 * sigma + 1) << name << " seed " << kSeed;
  };
  for (int c = 0; c < kNumSizeClasses; ++c)
    check(toString(static_cast<SizeClass>(c)), by_class[static_cast<size_t>(c)],
          opt.size_weight[static_cast<size_t>(c)] / wc);
  for (int s = 0; s < kNumStreamShapes; ++s)
    check(toString(static_cast<TriShape>(s)), by_shape[static_cast<size_t>(s)],
          opt.shape_weight[static_cast<size_t>(s)] / ws);
}

TEST(TriGen, AreasFallInTheirClassRanges) {
  const TriGenOptions opt;
  const auto tris = stream(kSeed, kStream, opt);
  std::array<double, kNumSizeClasses> sum{}, cov{};
  std::array<int, kNumSizeClasses> n{};
  double total = 0;
  long covered = 0;
  for (const auto& t : tris) {
    const double a = areaOf(t);
    total += a;
    const long c = coveredPixels(t, opt.width, opt.height);
    covered += c;
    cov[static_cast<size_t>(t.size)] += c;
    if (t.shape == TriShape::ZeroArea) {
      ASSERT_EQ(signedArea2(t), 0.0) << "seed " << kSeed << " triangle " << t.id;
      continue;
    }
    const AreaRange r = areaRange(t.size, opt);
    ASSERT_GE(a, r.lo * (1 - 1e-9)) << t.kind() << " triangle " << t.id << " seed " << kSeed;
    ASSERT_LE(a, r.hi * (1 + 1e-9)) << t.kind() << " triangle " << t.id << " seed " << kSeed;
    sum[static_cast<size_t>(t.size)] += a;
    ++n[static_cast<size_t>(t.size)];
  }
  for (int c = 0; c < kNumSizeClasses; ++c)
    std::printf("mean area %-7s %10.4g px^2, covered pixels %10.4g (%d)\n",
                toString(static_cast<SizeClass>(c)), sum[static_cast<size_t>(c)] / n[static_cast<size_t>(c)],
                cov[static_cast<size_t>(c)] / n[static_cast<size_t>(c)], n[static_cast<size_t>(c)]);
  const double mean_area = total / kStream, mean_covered = double(covered) / kStream;
  std::printf("mean area %.2f px^2, mean covered pixels %.2f (seed %llu, %d triangles)\n",
              mean_area, mean_covered, static_cast<unsigned long long>(kSeed), kStream);
  EXPECT_GE(mean_covered, 30);
  EXPECT_LE(mean_covered, 100);
}

TEST(TriGen, CoordinatesStayInTheGuardBand) {
  for (double g : {1024.0, 300.0, 20000.0}) {
    TriGenOptions opt;
    opt.guard_band = g;
    const Box box = guardBox(opt);
    EXPECT_GE(box.x0, -kTriGenMaxCoord);
    EXPECT_LE(box.x1, kTriGenMaxCoord);
    for (const auto& t : stream(kSeed, kStream / 2, opt))
      for (const auto& v : t.v) {
        ASSERT_TRUE(v.x >= box.x0 && v.x <= box.x1 && v.y >= box.y0 && v.y <= box.y1)
            << t.kind() << " triangle " << t.id << " guard " << g << " (" << v.x << ", " << v.y << ")";
        ASSERT_LE(std::fabs(v.x), kTriGenMaxCoord);
        ASSERT_LE(std::fabs(v.y), kTriGenMaxCoord);
      }
  }
}

TEST(TriGen, ShapesHaveTheirProperties) {
  const TriGenOptions opt;
  const double W = opt.width, H = opt.height;
  const double grid = std::ldexp(1.0, opt.subpixel_bits + 1);  // half-subpixel lattice
  int near_h = 0, near_v = 0, exact_h = 0, exact_v = 0, thin = 0;
  int cut_off[2] = {0, 0}, cut_odd = 0, cut_even = 0;
  int snap_centre = 0, snap_sub = 0, snap_half = 0;
  int zero_repeat = 0, zero_collinear = 0, off_corner = 0;
  int cw = 0, ccw = 0, flat = 0, ends = 0;
  for (const auto& t : stream(kSeed, kStream, opt)) {
    const double a2 = signedArea2(t);
    cw += a2 > 0;
    ccw += a2 < 0;
    const Box b = bboxOf(t);
    switch (t.shape) {
      case TriShape::Sliver: {
        const double aspect = longestEdge2(t) / (2 * areaOf(t));  // longest edge / its height
        ASSERT_LE(aspect, 1.0001e4) << "triangle " << t.id;
        if (t.size != SizeClass::Screen) {
          ASSERT_GE(aspect, 10 * (1 - 1e-9)) << "triangle " << t.id;
        }
        thin += aspect > 1000;
        bool nh = false, nv = false, eh = false, ev = false;
        for (int k = 0; k < 3; ++k) {
          const GenVertex &p = t.v[static_cast<size_t>(k)], &q = t.v[static_cast<size_t>((k + 1) % 3)];
          const double dx = std::fabs(q.x - p.x), dy = std::fabs(q.y - p.y);
          const double len2 = dx * dx + dy * dy;
          if (len2 < 0.9 * longestEdge2(t)) continue;  // only the long edges
          eh |= dy == 0;
          ev |= dx == 0;
          nh |= dy > 0 && dy <= 1e-2 * dx;
          nv |= dx > 0 && dx <= 1e-2 * dy;
        }
        near_h += nh;
        near_v += nv;
        exact_h += eh;
        exact_v += ev;
        break;
      }
      case TriShape::CutPoint: {
        const double off = t.v[0].x - std::floor(t.v[0].x);
        ASSERT_TRUE(off == 0 || off == 0.5) << "triangle " << t.id;
        ++cut_off[off == 0.5];
        for (const auto& v : t.v) {
          ASSERT_EQ(v.x - std::floor(v.x), off) << "triangle " << t.id;
          ASSERT_EQ(v.y - std::floor(v.y), off) << "triangle " << t.id;
        }
        const double dx = t.v[1].x - t.v[0].x;
        (std::fmod(std::fabs(dx), 2.0) == 1.0 ? cut_odd : cut_even)++;
        break;
      }
      case TriShape::Snapped:
        for (const auto& v : t.v)
          for (double c : {v.x, v.y}) {
            ASSERT_EQ(c * grid, std::floor(c * grid)) << "triangle " << t.id << " " << c;
            if (c - std::floor(c) == 0.5) {
              ++snap_centre;
            } else if (std::fmod(c * grid, 2.0) != 0) {
              ++snap_half;
            } else {
              ++snap_sub;
            }
          }
        break;
      case TriShape::ZeroArea: {
        bool rep = false;
        for (int k = 0; k < 3; ++k) {
          const GenVertex &p = t.v[static_cast<size_t>(k)], &q = t.v[static_cast<size_t>((k + 1) % 3)];
          rep |= p.x == q.x && p.y == q.y;
        }
        (rep ? zero_repeat : zero_collinear)++;
        break;
      }
      case TriShape::OffScreen: {
        // Partly outside: the bbox meets the viewport and leaves it.
        ASSERT_TRUE(b.x1 >= 0 && b.x0 <= W && b.y1 >= 0 && b.y0 <= H) << "triangle " << t.id;
        ASSERT_TRUE(b.x0 < 0 || b.x1 > W || b.y0 < 0 || b.y1 > H) << "triangle " << t.id;
        off_corner += (b.x0 < 0 || b.x1 > W) && (b.y0 < 0 || b.y1 > H);
        break;
      }
      case TriShape::Regular:
        if (t.size != SizeClass::Screen) {
          ASSERT_TRUE(b.x0 >= 0 && b.x1 <= W && b.y0 >= 0 && b.y1 <= H) << "triangle " << t.id;
        }
        break;
      default:
        FAIL() << "unexpected shape in the stream";
    }
    flat += t.v[0].attr == t.v[1].attr && t.v[1].attr == t.v[2].attr;
    for (const auto& v : t.v)
      for (int k = 0; k < opt.num_attr; ++k) {
        const double x = v.attr[static_cast<size_t>(k)];
        const AttrRange r = opt.attr_range[static_cast<size_t>(k)];
        ASSERT_TRUE(x >= r.lo && x <= r.hi) << "triangle " << t.id;
        ends += x == r.lo || x == r.hi;
      }
  }
  std::printf("slivers: near-horizontal %d, near-vertical %d, exactly horizontal %d, exactly "
              "vertical %d, aspect > 1000: %d\n", near_h, near_v, exact_h, exact_v, thin);
  std::printf("cut points: on corners %d, on centres %d; dx odd %d, even %d\n", cut_off[0],
              cut_off[1], cut_odd, cut_even);
  std::printf("snapped coordinates: pixel centres %d, subpixel points %d, half-subpixels %d\n",
              snap_centre, snap_sub, snap_half);
  std::printf("zero area: repeated vertex %d, collinear %d; off-screen at a corner %d\n",
              zero_repeat, zero_collinear, off_corner);
  std::printf("windings: area2 > 0 %d, < 0 %d; flat attributes %d\n", cw, ccw, flat);
  for (int n : {near_h, near_v, exact_h, exact_v, thin, cut_off[0], cut_off[1], cut_odd, cut_even,
                snap_centre, snap_sub, snap_half, zero_repeat, zero_collinear, off_corner})
    EXPECT_GT(n, 100);
  EXPECT_NEAR(cw, ccw, 0.03 * (cw + ccw));
  EXPECT_NEAR(flat, 0.1 * kStream, 0.01 * kStream);
  EXPECT_GT(ends, kStream / 10);
}

TEST(TriGen, AttributesFollowTheOptions) {
  TriGenOptions opt;
  opt.num_attr = 6;
  opt.attr_range[5] = {-3, -2};
  for (const auto& t : stream(kSeed, 2000, opt))
    for (const auto& v : t.v) {
      ASSERT_TRUE(v.attr[5] >= -3 && v.attr[5] <= -2);
      ASSERT_EQ(v.attr[6], 0.0);  // unused slots stay 0
    }
}

TEST(TriGen, RejectsImpossibleOptions) {
  TriGenOptions bad;
  bad.num_attr = kTriGenMaxAttr + 1;
  EXPECT_THROW(TriangleGenerator(1, bad), std::invalid_argument);
  bad = {};
  bad.size_weight = {0, 0, 0, 0, 0};
  EXPECT_THROW(TriangleGenerator(1, bad), std::invalid_argument);
  bad = {};
  bad.shape_weight[2] = -1;
  EXPECT_THROW(TriangleGenerator(1, bad), std::invalid_argument);
  bad = {};
  bad.width = 0;
  EXPECT_THROW(TriangleGenerator(1, bad), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Meshes

using Point = std::pair<double, double>;
using Edge = std::pair<Point, Point>;

// Every directed edge once; every edge either interior (both directions) or on the boundary
// predicate; all triangles of one winding with area.
void checkSharedEdges(const std::vector<GenTriangle>& tris, bool (*on_boundary)(const Edge&, const Box&),
                      const Box& region, int* interior_edges) {
  std::map<Edge, int> directed;
  std::map<Point, std::array<double, kTriGenMaxAttr>> attrs;
  const bool positive = signedArea2(tris.at(0)) > 0;
  for (const auto& t : tris) {
    const double a2 = signedArea2(t);
    ASSERT_NE(a2, 0.0) << "triangle " << t.id;
    ASSERT_EQ(a2 > 0, positive) << "triangle " << t.id << " has the other winding";
    for (size_t k = 0; k < 3; ++k) {
      const GenVertex &p = t.v[k], &q = t.v[(k + 1) % 3];
      const Edge e{{p.x, p.y}, {q.x, q.y}};
      ASSERT_EQ(++directed[e], 1) << "directed edge used twice, triangle " << t.id;
      auto it = attrs.emplace(Point{p.x, p.y}, p.attr).first;
      ASSERT_EQ(it->second, p.attr) << "a shared vertex with other attributes";
    }
  }
  int interior = 0;
  for (const auto& [e, n] : directed) {
    const Edge rev{e.second, e.first};
    if (directed.count(rev)) {
      ++interior;
    } else {
      ASSERT_TRUE(on_boundary(e, region)) << "edge (" << e.first.first << ", " << e.first.second
                                          << ") - (" << e.second.first << ", " << e.second.second
                                          << ") used once but not on the boundary";
    }
  }
  *interior_edges = interior / 2;
}

bool onRectBoundary(const Edge& e, const Box& r) {
  const auto [p, q] = e;
  return (p.first == r.x0 && q.first == r.x0) || (p.first == r.x1 && q.first == r.x1) ||
         (p.second == r.y0 && q.second == r.y0) || (p.second == r.y1 && q.second == r.y1);
}

TEST(SharedEdgeMesh, InteriorEdgesAreSharedExactlyWithOppositeOrientation) {
  const TriGenOptions opt;
  std::mt19937_64 rng(kSeed);
  int snapped_vertices = 0;
  for (const auto& [cols, rows, region, winding] :
       {std::tuple<int, int, Box, int>{16, 12, Box{0, 0, 0, 0}, 0},
        {40, 40, Box{10.25, 3.5, 200.75, 100}, 1},
        {200, 170, Box{0, 0, 0, 0}, -1},  // cells of ~3 px: most snaps are refused
        {3, 2, Box{-300, -200, 700, 650}, 0},
        {1, 1, Box{0.5, 0.5, 1.5, 1.5}, 1}}) {
    MeshGenOptions m;
    m.x0 = region.x0;
    m.y0 = region.y0;
    m.x1 = region.x1;
    m.y1 = region.y1;
    m.winding = winding;
    m.first_id = 7;
    const auto tris = makeSharedEdgeMesh(rng, opt, cols, rows, m);
    ASSERT_EQ(tris.size(), static_cast<size_t>(2 * cols * rows));
    const Box r = region.x1 > region.x0 ? region : Box{0, 0, double(opt.width), double(opt.height)};
    int interior = 0;
    checkSharedEdges(tris, onRectBoundary, r, &interior);
    // Euler: a triangulated rectangle of cols x rows cells has 3 cols rows - cols - rows
    // interior edges.
    EXPECT_EQ(interior, 3 * cols * rows - cols - rows) << cols << " x " << rows;
    double area = 0;
    for (const auto& t : tris) {
      area += areaOf(t);
      EXPECT_EQ(t.shape, TriShape::MeshGrid);
      if (winding != 0) {
        EXPECT_EQ(signedArea2(t) > 0, winding > 0);
      }
    }
    EXPECT_NEAR(area, (r.x1 - r.x0) * (r.y1 - r.y0), 1e-9 * (r.x1 - r.x0) * (r.y1 - r.y0));
    EXPECT_EQ(tris.front().id, 7u);
    EXPECT_EQ(tris.back().id, 7u + tris.size() - 1);
    for (const auto& t : tris)
      for (const auto& v : t.v)
        for (double c : {v.x, v.y}) snapped_vertices += c - std::floor(c) == 0.5 || c == std::floor(c);
  }
  EXPECT_GT(snapped_vertices, 500);
}

TEST(SharedEdgeMesh, CoversItsRegionOnce) {
  const TriGenOptions opt;
  std::mt19937_64 rng(kSeed + 5);
  const auto tris = makeSharedEdgeMesh(rng, opt, 10, 8);
  std::mt19937_64 pts(99);
  for (int i = 0; i < 3000; ++i) {
    const double x = (pts() >> 11) * 0x1.0p-53 * 512, y = (pts() >> 11) * 0x1.0p-53 * 512;
    int hits = 0;
    for (const auto& t : tris) {
      const double s = signedArea2(t) > 0 ? 1 : -1;
      bool in = true;
      for (size_t k = 0; k < 3; ++k) {
        const GenVertex &p = t.v[k], &q = t.v[(k + 1) % 3];
        in = in && s * ((q.x - p.x) * (y - p.y) - (x - p.x) * (q.y - p.y)) > 0;
      }
      hits += in;
    }
    ASSERT_EQ(hits, 1) << "point (" << x << ", " << y << ")";
  }
}

TEST(SharedEdgeMesh, RejectsBadArguments) {
  const TriGenOptions opt;
  std::mt19937_64 rng(1);
  EXPECT_THROW(makeSharedEdgeMesh(rng, opt, 0, 4), std::invalid_argument);
  MeshGenOptions m;
  m.jitter = 0.5;
  EXPECT_THROW(makeSharedEdgeMesh(rng, opt, 4, 4, m), std::invalid_argument);
  m = {};
  m.x0 = -5000;
  m.x1 = 10;
  m.y1 = 10;
  EXPECT_THROW(makeSharedEdgeMesh(rng, opt, 4, 4, m), std::invalid_argument);
}

TEST(FanMesh, ClosedFanSharesEveryInteriorEdge) {
  const TriGenOptions opt;
  std::mt19937_64 rng(kSeed);
  for (const auto& [cx, cy, radius, segments] :
       {std::tuple<double, double, double, int>{256, 256, 200, 64}, {100.5, 80.5, 3, 5},
        {0, 512, 300, 3}, {400.25, 10, 40, 200}}) {
    const auto tris = makeFanMesh(rng, opt, cx, cy, radius, segments);
    ASSERT_EQ(tris.size(), static_cast<size_t>(segments));
    int interior = 0;
    // Edges used once are the rim: neither end is the centre.
    const GenVertex c = tris[0].v[0];
    auto rim = [](const Edge& e, const Box& centre) {
      const Point p{centre.x0, centre.y0};
      return e.first != p && e.second != p;
    };
    checkSharedEdges(tris, rim, Box{c.x, c.y, c.x, c.y}, &interior);
    EXPECT_EQ(interior, segments);  // every spoke, twice
    for (const auto& t : tris) EXPECT_EQ(t.shape, TriShape::MeshFan);
  }
}

}  // namespace
}  // namespace shd
