// builtin:sphere (scene/sphere.h): idx3d's SPHERE(1, 64) and the default camera.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "scene/sphere.h"
#include "test_util.h"

namespace shd {
namespace {

using testutil::centroid;
using testutil::outwardFaceNormal;

constexpr double kPiT = 3.14159265358979323846;

double triangleArea(const Mesh& m, const std::array<uint32_t, 3>& t) {
  const Vec3 a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
  return 0.5 * length(cross(b - a, c - a));
}

TEST(Idx3dSphere, CountsOfTheDefaultSphere) {
  const Mesh m = idx3dSphere(1.0, 64);
  EXPECT_EQ(m.positions.size(), 4160u);
  EXPECT_EQ(m.normals.size(), 4160u);
  EXPECT_EQ(m.triangles.size(), 8190u);
  for (const auto& t : m.triangles)
    for (uint32_t v : t) ASSERT_LT(v, m.positions.size());
}

TEST(Idx3dSphere, CountsFollowTheFormulaForOtherSegmentCounts) {
  for (int s : {4, 5, 8, 17, 64, 100}) {
    const Mesh m = idx3dSphere(2.5, s);
    EXPECT_EQ(m.positions.size(), static_cast<size_t>((s + 1) * s)) << "segments " << s;
    EXPECT_EQ(m.triangles.size(), static_cast<size_t>(2 * (s * s - 1))) << "segments " << s;
    EXPECT_EQ(idx3dSphereVertexCount(s), (s + 1) * s);
    EXPECT_EQ(idx3dSphereTriangleCount(s), 2 * (s * s - 1));
  }
}

// sphere.h: 4 degenerate triangles per column pair (poles) plus the 2 (s-1) of the seam strip,
// all with exactly zero area; the rest have area.
TEST(Idx3dSphere, DegenerateTrianglesAreThePolesAndTheSeamExactly) {
  const Mesh m = idx3dSphere(1.0, 64);
  int zero = 0;
  double min_real = 1e9;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const double a = triangleArea(m, m.triangles[t]);
    if (a == 0.0) {
      ++zero;
      const bool seam = t >= 8064;
      const size_t within = t % 126;  // position inside a column pair
      const bool pole = within == 0 || within == 123 || within == 124 || within == 125;
      EXPECT_TRUE(seam || pole) << "triangle " << t << " has zero area";
    } else {
      min_real = std::min(min_real, a);
    }
  }
  EXPECT_EQ(zero, 4 * 64 + 126);
  EXPECT_EQ(static_cast<int>(m.triangles.size()) - zero, 64 * 122);
  EXPECT_GT(min_real, 1e-5);  // the smallest real triangles are the cap triangles
}

TEST(Idx3dSphere, PositionsLieOnTheSphere) {
  for (double r : {1.0, 0.25, 7.0}) {
    const Mesh m = idx3dSphere(r, 64);
    for (size_t v = 0; v < m.positions.size(); ++v)
      ASSERT_NEAR(length(m.positions[v]), r, 1e-12 * r) << "vertex " << v << " radius " << r;
  }
}

TEST(Idx3dSphere, ProfileIsIdx3dsPathSweptAboutY) {
  const int s = 64;
  const Mesh m = idx3dSphere(1.0, s);
  // Node i of column j: latitude pi (1/2 - i/(s-2)), azimuth -2 pi j / s (x toward -z).
  for (int j = 0; j <= s; ++j)
    for (int i = 0; i < s; ++i) {
      const Vec3 p = m.positions[static_cast<size_t>(i + s * j)];
      const double phi = kPiT * (0.5 - std::min(i, s - 2) / double(s - 2));
      const double beta = 2 * kPiT * j / s;
      ASSERT_NEAR(p.y, std::sin(phi), 1e-15);
      ASSERT_NEAR(p.x, std::cos(phi) * std::cos(beta), 1e-15);
      ASSERT_NEAR(p.z, -std::cos(phi) * std::sin(beta), 1e-15);
    }
  // Exact coincidences: poles, the duplicate south pole, the closing column, mirror symmetry.
  for (int j = 0; j <= s; ++j) {
    const Vec3 n = m.positions[static_cast<size_t>(s * j)];
    const Vec3 a = m.positions[static_cast<size_t>(s - 2 + s * j)];
    const Vec3 b = m.positions[static_cast<size_t>(s - 1 + s * j)];
    EXPECT_TRUE(n.x == 0 && n.y == 1 && n.z == 0) << "north pole of column " << j;
    EXPECT_TRUE(a.x == 0 && a.y == -1 && a.z == 0) << "south pole of column " << j;
    EXPECT_TRUE(b.x == 0 && b.y == -1 && b.z == 0) << "duplicate south pole of column " << j;
  }
  for (int i = 0; i < s; ++i) {
    const Vec3 p0 = m.positions[static_cast<size_t>(i)];
    const Vec3 ps = m.positions[static_cast<size_t>(i + s * s)];
    EXPECT_TRUE(p0.x == ps.x && p0.y == ps.y && p0.z == ps.z) << "seam node " << i;
    const Vec3 q = m.positions[static_cast<size_t>(s - 2 - std::min(i, s - 2))];
    EXPECT_TRUE(q.x == p0.x && q.y == -p0.y) << "mirror of node " << i;
  }
}

TEST(Idx3dSphere, FacesWithAreaAreWoundOutwardInIdx3dOrder) {
  const Mesh m = idx3dSphere(1.0, 64);
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    if (triangleArea(m, m.triangles[t]) == 0.0) continue;
    const Vec3 n = normalize(outwardFaceNormal(m, m.triangles[t]));
    const Vec3 c = normalize(centroid(m, m.triangles[t]));
    ASSERT_GT(dot(n, c), 0.99) << "triangle " << t;
  }
}

TEST(Idx3dSphere, NormalsAreUnitAndOutward) {
  const Mesh m = idx3dSphere(1.0, 64);
  // Largest angle to the radial direction, degrees: inner rings, rings 10..52, everything.
  double worst_inner = 0, worst_mid = 0, worst_any = 0;
  for (size_t v = 0; v < m.normals.size(); ++v) {
    const Vec3 n = m.normals[v];
    ASSERT_NEAR(length(n), 1.0, 1e-12) << "vertex " << v;
    const double c = std::min(1.0, dot(n, m.positions[v]));
    ASSERT_GT(c, 0.99) << "vertex " << v << " normal not outward";
    const double deg = std::acos(c) * 180 / kPiT;
    worst_any = std::max(worst_any, deg);
    const int i = static_cast<int>(v % 64), j = static_cast<int>(v / 64);
    if (i > 0 && i < 62 && j > 0 && j < 64) worst_inner = std::max(worst_inner, deg);
    if (i >= 10 && i <= 52 && j > 0 && j < 64) worst_mid = std::max(worst_mid, deg);
  }
  // Inner vertices see faces on all sides: their area-weighted normal is nearly radial, least so
  // next to the caps (measured 0.49 deg at rings 1 and 61, 0.08 deg at ring 10). Poles and seam
  // are one-sided (sphere.h): measured 1.45 deg (pole) and 2.85 deg (seam at the equator).
  EXPECT_LT(worst_inner, 0.5);
  EXPECT_LT(worst_mid, 0.08);
  EXPECT_LT(worst_any, 2.9);
  EXPECT_GT(worst_any, 2.8);  // they really are one-sided, as in idx3d
}

TEST(Idx3dSphere, RejectsBadArguments) {
  EXPECT_THROW(idx3dSphere(1.0, 3), std::invalid_argument);
  EXPECT_THROW(idx3dSphere(0.0, 64), std::invalid_argument);
  EXPECT_THROW(idx3dSphere(-1.0, 64), std::invalid_argument);
}

TEST(Camera, DefaultFrameIsTheWorldFrameShiftedByThree) {
  const Camera cam;
  const CameraBasis b = cameraBasis(cam);
  EXPECT_TRUE(b.right.x == 1 && b.right.y == 0 && b.right.z == 0);
  EXPECT_TRUE(b.up.x == 0 && b.up.y == 1 && b.up.z == 0);
  EXPECT_TRUE(b.forward.x == 0 && b.forward.y == 0 && b.forward.z == 1);
  const Vec3 p = toCameraSpace(b, cam, {0.25, -0.5, 1.0});
  EXPECT_EQ(p.x, 0.25);
  EXPECT_EQ(p.y, -0.5);
  EXPECT_EQ(p.z, 4.0);
}

TEST(Camera, BasisIsOrthonormalForAnObliqueView) {
  Camera cam;
  cam.eye = {2, 3, -4};
  cam.target = {0.5, -1, 1};
  const CameraBasis b = cameraBasis(cam);
  EXPECT_NEAR(length(b.right), 1, 1e-15);
  EXPECT_NEAR(length(b.up), 1, 1e-15);
  EXPECT_NEAR(length(b.forward), 1, 1e-15);
  EXPECT_NEAR(dot(b.right, b.up), 0, 1e-15);
  EXPECT_NEAR(dot(b.right, b.forward), 0, 1e-15);
  EXPECT_NEAR(dot(b.up, b.forward), 0, 1e-15);
  EXPECT_NEAR(b.right.y, 0, 1e-15);  // no roll: right stays horizontal
  EXPECT_GT(b.up.y, 0);
  // The target projects to the screen centre.
  const Vec3 t = toCameraSpace(b, cam, cam.target);
  EXPECT_NEAR(t.x, 0, 1e-15);
  EXPECT_NEAR(t.y, 0, 1e-15);
  EXPECT_NEAR(t.z, length(cam.target - cam.eye), 1e-14);
  // Straight down still gives a frame.
  cam.eye = {0, 5, 0};
  cam.target = {0, 0, 0};
  const CameraBasis d = cameraBasis(cam);
  EXPECT_NEAR(length(d.right), 1, 1e-15);
  EXPECT_NEAR(dot(d.right, d.forward), 0, 1e-15);
}

TEST(ProjectFrontFaces, DefaultSilhouetteMatchesTheAnalyticRadius) {
  const Mesh m = idx3dSphere(1.0, 64);
  const Camera cam;
  const auto tris = projectFrontFaces(m, cam);
  ASSERT_FALSE(tris.empty());
  // Tangent cone from distance 3 to a unit sphere: tan(half angle) = 1 / sqrt(3^2 - 1).
  const double r_px = 512.0 / std::sqrt(8.0);  // 181.02 px
  double xmin = 1e9, xmax = -1e9, ymin = 1e9, ymax = -1e9, rmax = 0;
  for (const auto& t : tris)
    for (const auto& v : t.v) {
      xmin = std::min(xmin, v.x);
      xmax = std::max(xmax, v.x);
      ymin = std::min(ymin, v.y);
      ymax = std::max(ymax, v.y);
      const double r = std::hypot(v.x - 256, v.y - 256);
      rmax = std::max(rmax, r);
      // Vertices lie on the sphere, so none projects outside its silhouette.
      ASSERT_LE(r, r_px + 1e-9) << "triangle " << t.id;
    }
  std::printf("front faces %zu, screen bbox x [%.3f, %.3f] y [%.3f, %.3f], max radius %.3f "
              "(analytic %.3f)\n",
              tris.size(), xmin, xmax, ymin, ymax, rmax, r_px);
  EXPECT_NEAR(rmax, r_px, 1.0);
  EXPECT_NEAR(xmin, 256 - r_px, 1.0);
  EXPECT_NEAR(xmax, 256 + r_px, 1.0);
  EXPECT_NEAR(ymin, 256 - r_px, 1.0);
  EXPECT_NEAR(ymax, 256 + r_px, 1.0);
}

TEST(ProjectFrontFaces, FrontFacesAreThoseFacingTheEye) {
  const Mesh m = idx3dSphere(1.0, 64);
  const Camera cam;
  const auto tris = projectFrontFaces(m, cam);
  // Independent 3D rule: the outward face normal points to the eye.
  std::vector<bool> facing(m.triangles.size(), false);
  size_t n3d = 0;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const auto& tri = m.triangles[t];
    facing[t] = dot(outwardFaceNormal(m, tri), cam.eye - m.positions[tri[0]]) > 0;
    n3d += facing[t];
  }
  EXPECT_EQ(tris.size(), n3d);
  uint32_t prev = 0;
  for (size_t k = 0; k < tris.size(); ++k) {
    const auto& t = tris[k];
    ASSERT_TRUE(facing[t.id]) << "triangle " << t.id;
    if (k > 0) {
      ASSERT_GT(t.id, prev) << "mesh order";
    }
    prev = t.id;
    const auto &a = t.v[0], &b = t.v[1], &c = t.v[2];
    EXPECT_LT((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y), 0.0);
    for (const auto& v : t.v) {
      EXPECT_GE(v.z, 2.0 - 1e-12);  // the near cap: z in [-1, about -1/3], Z = z + 3
      EXPECT_LE(v.z, 3.0);
      EXPECT_NEAR(length(v.n), 1.0, 1e-12);
    }
  }
  // Plausible share: triangles are uniform in (latitude band, azimuth), and a face is visible
  // when its direction n has n.z < -1/3, i.e. cos(lat) sin(azimuth) > 1/3. The share of the
  // (lat, azimuth) rectangle where that holds, times the 7808 triangles with area:
  const int N = 2000;
  int inside = 0;
  for (int a = 0; a < N; ++a)
    for (int b = 0; b < N; ++b) {
      const double lat = kPiT * ((a + 0.5) / N - 0.5), az = 2 * kPiT * (b + 0.5) / N;
      inside += std::cos(lat) * std::sin(az) > 1.0 / 3.0;
    }
  const double expected = 7808.0 * inside / (double(N) * N);
  std::printf("front faces %zu, expected about %.0f\n", tris.size(), expected);
  EXPECT_NEAR(static_cast<double>(tris.size()), expected, 0.03 * expected);
}

TEST(ProjectFrontFaces, TrianglesBehindTheCameraAreRejected) {
  const Mesh m = idx3dSphere(1.0, 64);
  Camera away;
  away.target = {0, 0, -6};  // looking away from the sphere
  EXPECT_TRUE(projectFrontFaces(m, away).empty());
  Camera close;
  close.eye = {0, 0, -1.05};  // the near cap crosses z_near = 0.1
  const auto tris = projectFrontFaces(m, close);
  EXPECT_FALSE(tris.empty());
  for (const auto& t : tris)
    for (const auto& v : t.v) ASSERT_GE(v.z, close.z_near);
  Camera inside;
  inside.eye = {0, 0, 0};
  inside.target = {0, 0, 1};  // from the centre every face is a back face
  EXPECT_TRUE(projectFrontFaces(m, inside).empty());
}

TEST(ProjectFrontFaces, ProjectionFormula) {
  Mesh m;
  m.positions = {{0, 0, 0}, {0.5, 0, 0}, {0, 0.5, 0}};
  m.normals = {{0, 0, -1}, {0, 0, -1}, {0, 0, -1}};
  m.triangles = {{0u, 2u, 1u}, {0u, 1u, 2u}};
  const auto tris = projectFrontFaces(m, Camera{});
  // (0,0,0) -> (256, 256); (0.5,0,0) -> x = 256 + 512*0.5/3; (0,0.5,0) -> y = 256 - 512*0.5/3.
  // On screen 0 -> 2 -> 1 goes centre, up, right: clockwise, a back face; 0 -> 1 -> 2 is
  // counter-clockwise, a front face (its outward normal (c - a) x (b - a) is -z, to the eye).
  ASSERT_EQ(tris.size(), 1u);
  EXPECT_EQ(tris[0].id, 1u);
  EXPECT_EQ(tris[0].v[0].x, 256.0);
  EXPECT_EQ(tris[0].v[0].y, 256.0);
  EXPECT_DOUBLE_EQ(tris[0].v[1].x, 256.0 + 512.0 * 0.5 / 3.0);
  EXPECT_EQ(tris[0].v[1].y, 256.0);
  EXPECT_DOUBLE_EQ(tris[0].v[2].y, 256.0 - 512.0 * 0.5 / 3.0);
  EXPECT_EQ(tris[0].v[2].z, 3.0);
  EXPECT_EQ(tris[0].v[0].n.z, -1.0);
}

}  // namespace
}  // namespace shd
