// Scenes (scene/scene.h): transforms, the torus and plane generators, the builtin scenes, mesh
// files through assimp (the assimp-testmodels package) and JSON scene files with their errors.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "scene/scene.h"
#include "test_util.h"

namespace shd {
namespace {

using testutil::centroid;
using testutil::outwardFaceNormal;

namespace fs = std::filesystem;

const std::string kModels = "/usr/share/assimp/models";
const std::string kScenes = std::string(SHD_SOURCE_DIR) + "/vectors/scenes";

// Every triangle with area is wound so that its outward face normal agrees with the vertex
// normals (their sum): the winding rule of sphere.h.
void expectWoundOutward(const Mesh& m, const std::string& what) {
  size_t bad = 0;
  for (const auto& t : m.triangles) {
    const Vec3 w = outwardFaceNormal(m, t);
    if (length(w) == 0) continue;
    if (dot(w, m.normals[t[0]] + m.normals[t[1]] + m.normals[t[2]]) <= 0) ++bad;
  }
  EXPECT_EQ(bad, 0u) << what;
}

void expectWellFormed(const Mesh& m, const std::string& what) {
  ASSERT_EQ(m.positions.size(), m.normals.size()) << what;
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const Vec3 p = m.positions[v], n = m.normals[v];
    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << what << " vertex " << v;
    ASSERT_NEAR(length(n), 1.0, 1e-12) << what << " vertex " << v;
  }
  for (const auto& t : m.triangles)
    for (uint32_t v : t) ASSERT_LT(v, m.positions.size()) << what;
}

// Front faces of every object of a scene and the screen bounding box of their vertices.
struct Projection {
  size_t triangles = 0, front = 0, front_in_viewport = 0;
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
};
Projection projectScene(const Scene& s, int only_object = -1) {
  Projection r;
  for (size_t o = 0; o < s.objects.size(); ++o) {
    if (only_object >= 0 && static_cast<int>(o) != only_object) continue;
    const Mesh w = worldMesh(s.objects[o]);
    r.triangles += w.triangles.size();
    for (const ScreenTriangle& t : projectFrontFaces(w, s.camera)) {
      ++r.front;
      bool inside = false;
      for (const ScreenVertexPos& v : t.v) {
        r.x0 = std::min(r.x0, v.x), r.x1 = std::max(r.x1, v.x);
        r.y0 = std::min(r.y0, v.y), r.y1 = std::max(r.y1, v.y);
        inside = inside || (v.x >= 0 && v.x <= s.camera.width && v.y >= 0 && v.y <= s.camera.height);
      }
      r.front_in_viewport += inside;
    }
  }
  return r;
}

// A scratch directory, removed at the end of the test.
struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / fmt::format("shd_test_scene_{}_{}", getpid(), counter()++);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  static int& counter() {
    static int c = 0;
    return c;
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = path / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  // The first `bytes` bytes of a file (bytes < 0: all but -bytes).
  std::string truncatedCopy(const std::string& src, const std::string& name, long bytes) const {
    std::ifstream in(src, std::ios::binary);
    std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t n = bytes >= 0 ? static_cast<size_t>(bytes) : data.size() - static_cast<size_t>(-bytes);
    return write(name, data.substr(0, n));
  }
};

// The SceneError message of loading `spec`, or "" if it loaded.
std::string sceneErrorOf(const std::string& spec) {
  try {
    loadScene(spec);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}
std::string meshErrorOf(const std::string& path) {
  try {
    loadMeshFile(path);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

// ---------------------------------------------------------------------------------------------
// Mat4

TEST(Mat4, QuarterTurnsAreExactAndFollowTheDocumentedSense) {
  // scene.h: positive about y turns +z toward +x; about x, +y toward +z; about z, +x toward +y.
  const Vec3 a = Mat4::rotateDeg({0, 90, 0}).direction({0, 0, 1});
  EXPECT_EQ(a.x, 1.0); EXPECT_EQ(a.y, 0.0); EXPECT_EQ(a.z, 0.0);
  const Vec3 b = Mat4::rotateDeg({90, 0, 0}).direction({0, 1, 0});
  EXPECT_EQ(b.x, 0.0); EXPECT_EQ(b.y, 0.0); EXPECT_EQ(b.z, 1.0);
  const Vec3 c = Mat4::rotateDeg({0, 0, 90}).direction({1, 0, 0});
  EXPECT_EQ(c.x, 0.0); EXPECT_EQ(c.y, 1.0); EXPECT_EQ(c.z, 0.0);
  const Vec3 d = Mat4::rotateDeg({0, -270, 0}).direction({0, 0, 1});  // -270 = +90
  EXPECT_EQ(d.x, 1.0); EXPECT_EQ(d.z, 0.0);
}

TEST(Mat4, RotationIsXThenYThenZ) {
  // +y --Rx(90)--> +z --Ry(90)--> +x --Rz(90)--> +y.
  const Vec3 p = Mat4::rotateDeg({90, 90, 90}).direction({0, 1, 0});
  EXPECT_NEAR(p.x, 0, 1e-15); EXPECT_NEAR(p.y, 1, 1e-15); EXPECT_NEAR(p.z, 0, 1e-15);
  const Mat4 r = Mat4::rotateDeg({30, 40, 50});
  const Mat4 composed = Mat4::rotateDeg({0, 0, 50}) * Mat4::rotateDeg({0, 40, 0}) * Mat4::rotateDeg({30, 0, 0});
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(r.m[i][j], composed.m[i][j], 1e-15);
  EXPECT_NEAR(r.determinant3(), 1.0, 1e-14);
}

TEST(Mat4, PointDirectionAndNormal) {
  const Mat4 t = Mat4::translate({1, 2, 3}) * Mat4::rotateDeg({0, 90, 0}) * Mat4::scale({2, 3, 4});
  const Vec3 p = t.point({1, 1, 1});  // scale (2,3,4), turn +z -> +x, +x -> -z, shift
  EXPECT_NEAR(p.x, 1 + 4, 1e-15); EXPECT_NEAR(p.y, 2 + 3, 1e-15); EXPECT_NEAR(p.z, 3 - 2, 1e-15);
  const Vec3 d = t.direction({1, 1, 1});
  EXPECT_NEAR(d.x, 4, 1e-15); EXPECT_NEAR(d.y, 3, 1e-15); EXPECT_NEAR(d.z, -2, 1e-15);
  // A normal stays perpendicular to every transformed tangent of its plane.
  const Mat4 s = Mat4::scale({1, 5, 0.5}) * Mat4::rotateDeg({20, 30, 40});
  const Vec3 n = normalize(Vec3{1, 2, 3}), t1 = cross(n, {0, 0, 1}), t2 = cross(n, t1);
  const Vec3 nw = s.normal(n);
  EXPECT_NEAR(length(nw), 1.0, 1e-15);
  EXPECT_NEAR(dot(nw, s.direction(t1)), 0.0, 1e-12);
  EXPECT_NEAR(dot(nw, s.direction(t2)), 0.0, 1e-12);
  EXPECT_GT(dot(nw, s.direction(n)), 0.0);  // still on the same side
  // A mirror keeps an outward normal outward: the +x face of a box mirrored in x faces -x.
  const Mat4 mx = Mat4::scale({-1, 1, 1});
  EXPECT_LT(mx.determinant3(), 0);
  EXPECT_EQ(mx.normal({1, 0, 0}).x, -1.0);
}

TEST(WorldMesh, MirroringTransformKeepsFrontFacesFront) {
  SceneObject o;
  o.mesh = torusMesh(1, 0.4, 32, 16);
  Camera cam;
  cam.eye = {0, 2, -3};
  size_t plain = 0;
  for (Vec3 sc : {Vec3{1, 1, 1}, Vec3{-1, 1, 1}, Vec3{1, 1, -1}, Vec3{-1, -1, -1}}) {
    o.transform = Mat4::scale(sc) * Mat4::rotateDeg({10, 0, 0});
    const Mesh w = worldMesh(o);
    expectWoundOutward(w, fmt::format("scale ({}, {}, {})j", sc.x, sc.y, sc.z));
    const auto front = projectFrontFaces(w, cam);
    if (plain == 0) plain = front.size();
    // The torus is symmetric in x and z, so a mirror shows (nearly) the same face count.
    EXPECT_NEAR(static_cast<double>(front.size()), static_cast<double>(plain), 0.05 * plain);
    for (const ScreenTriangle& t : front) {
      const Vec3 c = centroid(w, w.triangles[t.id]);
      EXPECT_GT(dot(outwardFaceNormal(w, w.triangles[t.id]), cam.eye - c), 0) << t.id;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Generators

TEST(TorusMesh, CountsExactPositionsAndAnalyticNormals) {
  const double R = 1.5, r = 0.5;
  const Mesh m = torusMesh(R, r, 48, 24);
  EXPECT_EQ(m.positions.size(), 48u * 24u);
  EXPECT_EQ(m.triangles.size(), 2u * 48u * 24u);
  expectWellFormed(m, "torus");
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const Vec3 p = m.positions[v];
    const double ring = std::hypot(p.x, p.z);
    const Vec3 centre = (R / ring) * Vec3{p.x, 0, p.z};  // nearest point of the centre circle
    EXPECT_NEAR(length(p - centre), r, 1e-15) << v;
    const Vec3 n = (1 / r) * (p - centre);
    EXPECT_NEAR(length(m.normals[v] - n), 0, 1e-15) << v;
  }
  // The quarter-turn vertices are exact: u = 0 outside (R + r, 0, 0), u = 90 deg at +z, top.
  EXPECT_EQ(m.positions[0].x, R + r); EXPECT_EQ(m.positions[0].y, 0.0); EXPECT_EQ(m.positions[0].z, 0.0);
  const Vec3 q = m.positions[12 * 24];  // i = 12 of 48: u = 90 deg
  EXPECT_EQ(q.x, 0.0); EXPECT_EQ(q.z, R + r);
  const Vec3 top = m.positions[6];  // j = 6 of 24: v = 90 deg, on top of the tube
  EXPECT_EQ(top.x, R); EXPECT_EQ(top.y, r); EXPECT_EQ(top.z, 0.0);
  expectWoundOutward(m, "torus");
}

TEST(TorusMesh, SeenFromOutsideAboutHalfTheFacesAreFront) {
  const Mesh m = torusMesh(1, 0.35, 48, 24);
  for (Vec3 eye : {Vec3{0, 0, -8}, Vec3{0, 5, -5}, Vec3{3, -4, 6}, Vec3{0, 8, 0.001}}) {
    Camera cam;
    cam.eye = eye;
    cam.px_per_unit = 100;
    const auto front = projectFrontFaces(m, cam);
    const double share = static_cast<double>(front.size()) / m.triangles.size();
    // From far away exactly half the area faces the eye; from a finite distance a bit less.
    EXPECT_GT(share, 0.40) << eye.x << "," << eye.y << "," << eye.z;
    EXPECT_LE(share, 0.50) << eye.x << "," << eye.y << "," << eye.z;
    for (const ScreenTriangle& t : front)
      ASSERT_GT(dot(outwardFaceNormal(m, m.triangles[t.id]), eye - centroid(m, m.triangles[t.id])), 0);
  }
}

TEST(TorusMesh, RejectsBadArguments) {
  EXPECT_THROW(torusMesh(1, 0.3, 2, 8), std::invalid_argument);
  EXPECT_THROW(torusMesh(1, 0.3, 8, 2), std::invalid_argument);
  EXPECT_THROW(torusMesh(1, 1, 8, 8), std::invalid_argument);
  EXPECT_THROW(torusMesh(1, 0, 8, 8), std::invalid_argument);
  EXPECT_THROW(torusMesh(1, -0.2, 8, 8), std::invalid_argument);
}

TEST(PlaneMesh, GridIsExactAndSymmetric) {
  const Mesh m = planeMesh(4, 2, 16);
  EXPECT_EQ(m.positions.size(), 17u * 17u);
  EXPECT_EQ(m.triangles.size(), 2u * 16u * 16u);
  expectWellFormed(m, "plane");
  double x0 = 1e9, x1 = -1e9, z0 = 1e9, z1 = -1e9;
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const Vec3 p = m.positions[v];
    EXPECT_EQ(p.y, 0.0);
    EXPECT_EQ(m.normals[v].y, 1.0);
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), z0 = std::min(z0, p.z), z1 = std::max(z1, p.z);
  }
  EXPECT_EQ(x0, -2.0); EXPECT_EQ(x1, 2.0); EXPECT_EQ(z0, -1.0); EXPECT_EQ(z1, 1.0);
  const Vec3 centre = m.positions[8 * 17 + 8];
  EXPECT_EQ(centre.x, 0.0); EXPECT_EQ(centre.z, 0.0);
  // Mirror symmetry: vertex (i, j) and (16 - i, j) have opposite x exactly.
  for (int i = 0; i <= 16; ++i)
    for (int j = 0; j <= 16; ++j) EXPECT_EQ(m.positions[i * 17 + j].x, -m.positions[(16 - i) * 17 + j].x);
  expectWoundOutward(m, "plane");
  EXPECT_THROW(planeMesh(0, 1, 4), std::invalid_argument);
  EXPECT_THROW(planeMesh(1, 1, 0), std::invalid_argument);
}

TEST(PlaneMesh, AllFrontFromAboveNoneFromBelow) {
  const Mesh m = planeMesh(2, 2, 8);
  Camera cam;
  cam.eye = {0.3, 3, -3};
  EXPECT_EQ(projectFrontFaces(m, cam).size(), m.triangles.size());
  cam.eye = {0.3, -3, -3};
  EXPECT_EQ(projectFrontFaces(m, cam).size(), 0u);
  cam.eye = {0, 4, 0.01};  // straight down (the up_world fallback of cameraBasis)
  EXPECT_EQ(projectFrontFaces(m, cam).size(), m.triangles.size());
}

// ---------------------------------------------------------------------------------------------
// Builtin scenes

TEST(BuiltinScenes, NamesLoad) {
  const auto names = builtinSceneNames();
  EXPECT_EQ(names, (std::vector<std::string>{"builtin:sphere", "builtin:plane", "builtin:torus",
                                             "builtin:materials"}));
  for (const std::string& n : names) {
    const Scene s = loadScene(n);
    EXPECT_EQ(s.name, n);
    ASSERT_FALSE(s.objects.empty()) << n;
    for (const SceneObject& o : s.objects) {
      expectWellFormed(o.mesh, n + " " + o.name);
      ASSERT_GE(o.material, 0);
      ASSERT_LT(o.material, static_cast<int>(s.materials.size()));
    }
    EXPECT_FALSE(s.lights.empty()) << n;
  }
  const std::string e = sceneErrorOf("builtin:cube");
  EXPECT_NE(e.find("builtin:cube"), std::string::npos) << e;
  EXPECT_NE(e.find("builtin:materials"), std::string::npos) << e;  // lists the known ones
}

TEST(BuiltinScenes, SphereIsTheDesignDefaultScene) {
  const Scene s = loadScene("builtin:sphere");
  // The default scene (model/scene/scene.h): 512x512, camera (0,0,-3) at the origin, 512 px per unit.
  EXPECT_EQ(s.camera.width, 512); EXPECT_EQ(s.camera.height, 512);
  EXPECT_EQ(s.camera.px_per_unit, 512.0);
  EXPECT_EQ(s.camera.eye.x, 0.0); EXPECT_EQ(s.camera.eye.y, 0.0); EXPECT_EQ(s.camera.eye.z, -3.0);
  EXPECT_EQ(s.camera.target.x, 0.0); EXPECT_EQ(s.camera.target.y, 0.0); EXPECT_EQ(s.camera.target.z, 0.0);
  EXPECT_EQ(s.camera.z_near, 0.1);
  EXPECT_EQ(s.ambient.x, 0.0); EXPECT_EQ(s.ambient.y, 0.0); EXPECT_EQ(s.ambient.z, 0.0);
  // One white directional light toward the upper left front: (-1, 1, -1) / sqrt 3.
  ASSERT_EQ(s.lights.size(), 1u);
  const Light& l = s.lights[0];
  EXPECT_EQ(l.kind, Light::Kind::Directional);
  const double k = 1 / std::sqrt(3.0);
  EXPECT_NEAR(l.direction.x, -k, 1e-16); EXPECT_NEAR(l.direction.y, k, 1e-16); EXPECT_NEAR(l.direction.z, -k, 1e-16);
  EXPECT_EQ(l.colour.x, 1.0); EXPECT_EQ(l.colour.y, 1.0); EXPECT_EQ(l.colour.z, 1.0);
  // Material: 0x3070C0, ks 1, kd 1, n 32, blinn.
  ASSERT_EQ(s.materials.size(), 1u);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.colour.x, 0x30 / 255.0); EXPECT_EQ(m.colour.y, 0x70 / 255.0); EXPECT_EQ(m.colour.z, 0xC0 / 255.0);
  EXPECT_EQ(m.kd, 1.0); EXPECT_EQ(m.ks, 1.0); EXPECT_EQ(m.shininess, 32.0); EXPECT_EQ(m.brdf, "blinn");
  // idx3d SPHERE(1, 64): 4160 vertices, 8190 triangles, untransformed.
  ASSERT_EQ(s.objects.size(), 1u);
  const SceneObject& o = s.objects[0];
  EXPECT_EQ(o.mesh.positions.size(), 4160u);
  EXPECT_EQ(o.mesh.triangles.size(), 8190u);
  EXPECT_EQ(o.material, 0);
  const Mesh ref = idx3dSphere(1, 64);
  for (size_t v = 0; v < ref.positions.size(); ++v) {
    ASSERT_EQ(o.mesh.positions[v].x, ref.positions[v].x);
    ASSERT_EQ(o.mesh.positions[v].y, ref.positions[v].y);
    ASSERT_EQ(o.mesh.positions[v].z, ref.positions[v].z);
  }
  EXPECT_EQ(o.mesh.triangles, ref.triangles);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_EQ(o.transform.m[i][j], i == j ? 1.0 : 0.0);
  // sphere.h: 2088 front faces, within the silhouette circle.
  const Projection p = projectScene(s);
  EXPECT_EQ(p.front, 2088u);
  EXPECT_EQ(p.front_in_viewport, 2088u);
}

TEST(BuiltinScenes, EachProjectsAPlausibleImage) {
  struct Expect {
    const char* name;
    size_t min_front, max_front;
    bool inside;  // every front face wholly inside the viewport
  };
  for (const Expect& e : {Expect{"builtin:sphere", 2088, 2088, true},
                          Expect{"builtin:plane", 7000, 8192, false},
                          Expect{"builtin:torus", 1500, 2048, true},
                          Expect{"builtin:materials", 5 * 750, 5 * 950, true}}) {
    const Scene s = loadScene(e.name);
    const Projection p = projectScene(s);
    fmt::print("{}: {} triangles, {} front faces, {} in the viewport, bbox x [{:.1f}, {:.1f}] y [{:.1f}, {:.1f}]\n",
               e.name, p.triangles, p.front, p.front_in_viewport, p.x0, p.x1, p.y0, p.y1);
    EXPECT_GE(p.front, e.min_front) << e.name;
    EXPECT_LE(p.front, e.max_front) << e.name;
    EXPECT_GT(p.front_in_viewport, p.front / 2) << e.name;
    if (e.inside) {
      EXPECT_GE(p.x0, 0) << e.name;
      EXPECT_LE(p.x1, s.camera.width) << e.name;
      EXPECT_GE(p.y0, 0) << e.name;
      EXPECT_LE(p.y1, s.camera.height) << e.name;
    }
  }
}

TEST(BuiltinScenes, MaterialsRowShowsEveryShininessSideBySide) {
  const Scene s = loadScene("builtin:materials");
  ASSERT_EQ(s.objects.size(), 5u);
  ASSERT_EQ(s.materials.size(), 5u);
  std::vector<double> ns;
  std::set<std::string> brdfs;
  std::set<std::array<double, 3>> colours;
  double prev_right = -1;
  for (size_t o = 0; o < 5; ++o) {
    const Material& m = s.materials[static_cast<size_t>(s.objects[o].material)];
    ns.push_back(m.shininess);
    brdfs.insert(m.brdf);
    colours.insert({m.colour.x, m.colour.y, m.colour.z});
    if (m.brdf == "cubic") {
      EXPECT_LE(m.shininess, 256);  // the cubic device's PROM range
    }
    const Projection p = projectScene(s, static_cast<int>(o));
    EXPECT_GT(p.x0, prev_right) << "sphere " << o << " overlaps its left neighbour";
    EXPECT_GT(p.x1 - p.x0, 60) << o;  // big enough to show a highlight
    prev_right = p.x1;
  }
  EXPECT_EQ(ns, (std::vector<double>{1, 8, 32, 200, 1000}));
  EXPECT_EQ(brdfs.size(), 5u);
  EXPECT_EQ(colours.size(), 5u);
}

// The plane scene's purpose (paper Fig. 4 c, d): with the renderer's infinite viewer the Blinn
// highlight on the plane is a streak toward the viewer and the Phong one a compact spot.
// Evaluated per pixel in double at the ray-plane hits, like the reference method.
TEST(BuiltinScenes, PlaneHighlightIsElongatedForBlinnAndCompactForPhong) {
  const Scene s = loadScene("builtin:plane");
  ASSERT_EQ(s.lights.size(), 1u);
  ASSERT_EQ(s.lights[0].kind, Light::Kind::Point);
  const double n = s.materials[0].shininess;
  const Camera& cam = s.camera;
  const CameraBasis b = cameraBasis(cam);
  const Vec3 V = -b.forward, N{0, 1, 0}, lp = s.lights[0].position;
  // The mirror direction of V at the origin points at the light: the peak is at the centre.
  const Vec3 mirror = 2 * dot(N, V) * N - V;
  EXPECT_NEAR(length(cross(mirror, normalize(lp))), 0, 1e-15);
  struct Box {
    int x0 = 1 << 20, x1 = -1, y0 = 1 << 20, y1 = -1, count = 0;
    void add(int x, int y) { x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y), ++count; }
  } blinn, phong;
  const Mesh w = worldMesh(s.objects[0]);
  double zmin = 1e9, zmax = -1e9, xmax = 0;
  for (const Vec3& p : w.positions) zmin = std::min(zmin, p.z), zmax = std::max(zmax, p.z), xmax = std::max(xmax, p.x);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const double X = (x + 0.5 - cam.width / 2.0) / cam.px_per_unit, Y = -(y + 0.5 - cam.height / 2.0) / cam.px_per_unit;
      const Vec3 d = b.forward + X * b.right + Y * b.up;
      if (d.y >= 0) continue;
      const Vec3 p = cam.eye + (-cam.eye.y / d.y) * d;
      if (std::fabs(p.x) > xmax || p.z < zmin || p.z > zmax) continue;
      const Vec3 L = normalize(lp - p), H = normalize(L + V), R = 2 * dot(N, L) * N - L;
      if (std::pow(std::max(0.0, dot(N, H)), n) > 0.1) blinn.add(x, y);
      if (std::pow(std::max(0.0, dot(R, V)), n) > 0.1) phong.add(x, y);
    }
  const int bw = blinn.x1 - blinn.x0 + 1, bh = blinn.y1 - blinn.y0 + 1;
  const int pw = phong.x1 - phong.x0 + 1, ph = phong.y1 - phong.y0 + 1;
  fmt::print("plane, lobe > 0.1: blinn {} px, {} x {} (x {}..{}, y {}..{}); phong {} px, {} x {} (x {}..{}, y {}..{})\n",
             blinn.count, bw, bh, blinn.x0, blinn.x1, blinn.y0, blinn.y1, phong.count, pw, ph,
             phong.x0, phong.x1, phong.y0, phong.y1);
  EXPECT_GT(bh, 2 * bw);           // a streak toward the viewer
  EXPECT_LT(ph, 1.5 * pw);         // nearly round
  EXPECT_GT(bh, 2 * ph);
  EXPECT_GT(blinn.count, 2000);    // clearly visible
  EXPECT_GT(phong.count, 2000);
  EXPECT_GT(phong.x0, 0); EXPECT_LT(phong.x1, cam.width - 1); EXPECT_LT(phong.y1, cam.height - 1);
  EXPECT_GT(blinn.x0, 0); EXPECT_LT(blinn.x1, cam.width - 1);
}

// ---------------------------------------------------------------------------------------------
// Mesh files through assimp

struct ModelCase {
  const char* path;  // under /usr/share/assimp/models
  size_t triangles;  // the model's own face count (after triangulation)
};
const ModelCase kModelCases[] = {
    {"Collada/teapots.DAE", 2976},          {"Collada/teapot_instancenodes.DAE", 1984},
    {"STL/Spider_binary.stl", 1312},        {"STL/Spider_ascii.stl", 1312},
    {"OBJ/spider.obj", 1312},               {"FBX/spider.fbx", 1312},
    {"COB/spider_4_3.cob", 1312},           {"STL/Wuson.stl", 3732},
    {"OBJ/WusonOBJ.obj", 3732},             {"PLY/Wuson.ply", 3732},
    {"OFF/Wuson.off", 3732},                {"X/Testwuson.X", 3732},
};

TEST(LoadMeshFile, TestModelsLoadFiniteWithUnitNormals) {
  for (const ModelCase& c : kModelCases) {
    const std::string path = kModels + "/" + c.path;
    ASSERT_TRUE(fs::exists(path)) << path << " missing: scripts/install_deps.sh installs assimp-testmodels";
    const Mesh m = loadMeshFile(path);
    fmt::print("{}: {} vertices, {} triangles\n", c.path, m.positions.size(), m.triangles.size());
    EXPECT_GT(m.positions.size(), 0u) << c.path;
    EXPECT_EQ(m.triangles.size(), c.triangles) << c.path;
    expectWellFormed(m, c.path);
    // No degenerate triangles, and every vertex is used.
    std::vector<bool> used(m.positions.size());
    for (const auto& t : m.triangles) {
      EXPECT_GT(length(outwardFaceNormal(m, t)), 0) << c.path;
      for (uint32_t v : t) used[v] = true;
    }
    EXPECT_EQ(std::count(used.begin(), used.end(), false), 0) << c.path;
  }
}

// Handedness (scene.h): after the z mirror, the winding says outward the way sphere.h does, so
// the front faces the camera sees carry normals pointing at it. Each model is framed by a
// camera on -z looking at its bounding box.
TEST(LoadMeshFile, WindingAndNormalsAgreeSoFrontFacesFaceTheCamera) {
  for (const ModelCase& c : kModelCases) {
    const Mesh m = loadMeshFile(kModels + "/" + c.path);
    Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    for (const Vec3& p : m.positions) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    const Vec3 centre = 0.5 * (lo + hi);
    const double radius = 0.5 * length(hi - lo);
    Camera cam;
    cam.target = centre;
    cam.eye = centre + Vec3{0.3 * radius, 0.5 * radius, -3 * radius};
    cam.px_per_unit = 512 * 3 / 2.2;
    const auto front = projectFrontFaces(m, cam);
    size_t agree = 0, facing = 0;
    for (const ScreenTriangle& t : front) {
      const auto& tri = m.triangles[t.id];
      const Vec3 nsum = m.normals[tri[0]] + m.normals[tri[1]] + m.normals[tri[2]];
      agree += dot(nsum, outwardFaceNormal(m, tri)) > 0;
      facing += t.v[0].n.z + t.v[1].n.z + t.v[2].n.z < 0;  // camera space: toward the eye is -Z
    }
    const double share = static_cast<double>(front.size()) / m.triangles.size();
    fmt::print("{}: {} of {} front ({:.0f}%), normals agree {:.1f}%, face the eye {:.1f}%\n", c.path,
               front.size(), m.triangles.size(), 100 * share, 100.0 * agree / front.size(),
               100.0 * facing / front.size());
    EXPECT_GT(share, 0.25) << c.path;
    EXPECT_LT(share, 0.75) << c.path;
    EXPECT_GT(agree, 0.9 * front.size()) << c.path;
    EXPECT_GT(facing, 0.8 * front.size()) << c.path;
  }
}

double signedVolume(const Mesh& m) {
  // The divergence theorem with sphere.h's outward normal (c - a) x (b - a): the enclosed volume
  // is sum a . (c x b) / 6, positive when the winding is outward (exact for a closed mesh; the
  // Wuson models have a few open edges, which leaves the sign alone).
  double vol = 0;
  for (const auto& t : m.triangles) vol += dot(m.positions[t[0]], cross(m.positions[t[2]], m.positions[t[1]])) / 6;
  return vol;
}

TEST(LoadMeshFile, WindingEnclosesPositiveVolume) {
  const double wuson = signedVolume(loadMeshFile(kModels + "/OBJ/WusonOBJ.obj"));
  EXPECT_GT(wuson, 0);
  for (const char* f : {"STL/Wuson.stl", "PLY/Wuson.ply", "X/Testwuson.X"})
    EXPECT_NEAR(signedVolume(loadMeshFile(kModels + "/" + f)), wuson, 1e-6 * wuson) << f;
  // OFF/Wuson.off lists every face clockwise (its first face is the OBJ's reversed): it loads
  // inside out, as written.
  EXPECT_NEAR(signedVolume(loadMeshFile(kModels + "/OFF/Wuson.off")), -wuson, 1e-6 * wuson);
  // The spiders' winding is outward in every format, also in the STL files, whose facet
  // normals point inward (loadMeshFile negates them; WindingAndNormalsAgree... checks that).
  for (const char* f : {"STL/Spider_binary.stl", "STL/Spider_ascii.stl", "OBJ/spider.obj", "COB/spider_4_3.cob"})
    EXPECT_GT(signedVolume(loadMeshFile(kModels + "/" + f)), 0) << f;
  const double ico = signedVolume(loadMeshFile(kScenes + "/icosphere.obj"));
  EXPECT_GT(ico, 0.85 * 4.0 / 3 * 3.14159265358979);  // an 80-face ball of radius 1
  EXPECT_LT(ico, 4.0 / 3 * 3.14159265358979);
}

TEST(LoadMeshFile, InvalidTestModelsGiveErrorsNamingTheFile) {
  for (const char* f : {"invalid/empty.obj", "invalid/empty.ply", "invalid/empty.off", "invalid/empty.3ds",
                        "invalid/empty.x", "invalid/empty.lwo", "invalid/empty.smd", "invalid/empty.ase",
                        "invalid/empty.md5mesh", "invalid/empty.raw", "invalid/malformed.obj",
                        "invalid/emptyIrrMesh.xml", "invalid/readme.txt", "OFF/invalid.off"}) {
    const std::string path = kModels + "/" + f;
    ASSERT_TRUE(fs::exists(path)) << path;
    const std::string e = meshErrorOf(path);
    fmt::print("{}\n", e);
    EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << f << ": " << e;
  }
  // malformed2.obj only references a missing material and has an empty face: the geometry
  // (a box without one side, 5 quads) is fine and loads.
  const Mesh m = loadMeshFile(kModels + "/invalid/malformed2.obj");
  EXPECT_EQ(m.triangles.size(), 10u);
}

// invalid/OutOfMemory.off declares 353535235358 vertices in 309 bytes; assimp allocates for
// them. loadMeshFile imports in a child process with a 4 GB limit (mesh_child.cpp): the file is
// a SceneError naming it and the limit, quickly, and this process's memory does not grow.
TEST(LoadMeshFile, OutOfMemoryModelIsRefusedByTheImportLimit) {
  const std::string path = kModels + "/invalid/OutOfMemory.off";
  ASSERT_TRUE(fs::exists(path));
  // Without the limit assimp takes 36 s and 15.8 GB on it.
  const std::string e = meshErrorOf(path);
  EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << e;
  EXPECT_NE(e.find("4096 MB"), std::string::npos) << e;
}

// A truncated COB file makes assimp 5.2 throw where nothing can catch it: std::terminate. In
// the import's child process that is a SceneError naming the file, the signal and assimp's
// last words, and this process goes on.
TEST(LoadMeshFile, AnImportThatAbortsIsAnError) {
  TempDir tmp;
  const std::string path = tmp.truncatedCopy(kModels + "/COB/molecule.cob", "cut.cob", 1000);
  const std::string e = meshErrorOf(path);
  EXPECT_EQ(e.rfind(path + ": assimp crashed on it (signal 6", 0), 0u) << e;
  EXPECT_NE(e.find("DeadlyImportError"), std::string::npos) << e;
}

TEST(LoadMeshFile, MissingFileAndDirectory) {
  EXPECT_EQ(meshErrorOf("/nonexistent/dir/mesh.obj"), "/nonexistent/dir/mesh.obj: no such file");
  EXPECT_EQ(meshErrorOf(kModels), kModels + ": it is a directory; inputs are read only from regular files");
}

TEST(LoadMeshFile, TruncatedFilesAreErrors) {
  TempDir tmp;
  struct Cut {
    const char* src;
    const char* name;
    long bytes;  // kept; < 0: all but
  };
  // A text file cut exactly after a complete face line is a valid smaller file and cannot be
  // told apart (OBJ, ASCII STL); these cuts can: an ASCII PLY whose faces are missing (assimp
  // leaves faces without indices), a binary PLY missing its last bytes, a binary STL shorter
  // than its triangle count, an OBJ cut before its faces, and a file cut inside its header.
  const long wuson_ply = static_cast<long>(fs::file_size(kModels + "/PLY/Wuson.ply"));
  const long spider_stl = static_cast<long>(fs::file_size(kModels + "/STL/Spider_binary.stl"));
  const long wuson_obj = static_cast<long>(fs::file_size(kModels + "/OBJ/WusonOBJ.obj"));
  for (const Cut& c : {Cut{"PLY/Wuson.ply", "half.ply", wuson_ply / 2},
                       Cut{"PLY/cube_binary.ply", "cut.ply", -20},
                       Cut{"STL/Spider_binary.stl", "half.stl", spider_stl / 2},
                       Cut{"OBJ/WusonOBJ.obj", "half.obj", wuson_obj / 2},
                       Cut{"OBJ/WusonOBJ.obj", "head.obj", 1000},
                       Cut{"PLY/Wuson.ply", "head.ply", 100}}) {
    const std::string path = tmp.truncatedCopy(kModels + "/" + c.src, c.name, c.bytes);
    const std::string e = meshErrorOf(path);
    fmt::print("{}\n", e);
    EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << c.src << " cut to " << c.bytes << ": '" << e << "'";
  }
}

TEST(LoadMeshFile, NonFinitePositionsAreErrors) {
  TempDir tmp;
  // 1e39 overflows assimp's float to infinity.
  const std::string path = tmp.write("inf.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string e = meshErrorOf(path);
  EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << e;
  EXPECT_NE(e.find("not finite"), std::string::npos) << e;
}

TEST(LoadMeshFile, ZeroNormalsAreReplacedByFaceNormalsOrRejected) {
  TempDir tmp;
  // A file normal of length zero: replaced by the face normal. The OBJ face is counter-
  // clockwise seen from +z (right-handed); after the z mirror its outward side is -z.
  const std::string one = tmp.write("zero_normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n");
  const Mesh m = loadMeshFile(one);
  ASSERT_EQ(m.triangles.size(), 1u);
  for (const Vec3& n : m.normals) {
    EXPECT_EQ(n.x, 0.0);
    EXPECT_EQ(n.y, 0.0);
    EXPECT_EQ(n.z, -1.0);
  }
  // A file without normals: assimp's smooth normals, the same direction.
  const Mesh g = loadMeshFile(tmp.write("no_normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  for (const Vec3& n : g.normals) EXPECT_NEAR(n.z, -1.0, 1e-7);
  // The same triangle both ways round shares its vertices: the face normals cancel.
  const std::string two = tmp.write("two_sided.obj",
                                    "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\nf 1//1 3//1 2//1\n");
  const std::string e = meshErrorOf(two);
  EXPECT_EQ(e.rfind(two + ": ", 0), 0u) << e;
  EXPECT_NE(e.find("zero-length normal"), std::string::npos) << e;
  // Only degenerate triangles: nothing to draw.
  const std::string flat = tmp.write("line.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  const std::string e2 = meshErrorOf(flat);
  EXPECT_EQ(e2.rfind(flat + ": ", 0), 0u) << e2;
}

TEST(LoadMeshFile, MirrorsZIntoTheLeftHandedFrame) {
  TempDir tmp;
  const Mesh m = loadMeshFile(tmp.write("p.obj", "v 1 2 3\nv 2 2 3\nv 1 3 3\nf 1 2 3\n"));
  ASSERT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.positions[0].x, 1.0); EXPECT_EQ(m.positions[0].y, 2.0); EXPECT_EQ(m.positions[0].z, -3.0);
  EXPECT_EQ(m.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));  // vertex order kept
  // The face is counter-clockwise seen from +z in the file: it faces +z there, -z here, i.e.
  // the default camera at z = -3 sees its front.
  Camera cam;
  cam.target = {1.3, 2.3, -3};
  cam.eye = {1.3, 2.3, -6};
  EXPECT_EQ(projectFrontFaces(m, cam).size(), 1u);
}

// ---------------------------------------------------------------------------------------------
// JSON scene files

TEST(SceneFile, ShippedScenesLoad) {
  const Scene a = loadScene(kScenes + "/sphere.json");
  const Scene b = loadScene("builtin:sphere");
  EXPECT_EQ(a.name, kScenes + "/sphere.json");
  EXPECT_EQ(a.camera.eye.z, b.camera.eye.z); EXPECT_EQ(a.camera.px_per_unit, b.camera.px_per_unit);
  EXPECT_EQ(a.camera.width, b.camera.width); EXPECT_EQ(a.camera.z_near, b.camera.z_near);
  ASSERT_EQ(a.lights.size(), 1u);
  EXPECT_EQ(a.lights[0].direction.x, b.lights[0].direction.x);
  EXPECT_EQ(a.lights[0].direction.y, b.lights[0].direction.y);
  EXPECT_EQ(a.lights[0].direction.z, b.lights[0].direction.z);
  ASSERT_EQ(a.materials.size(), 1u);
  EXPECT_EQ(a.materials[0].colour.x, b.materials[0].colour.x);
  EXPECT_EQ(a.materials[0].colour.y, b.materials[0].colour.y);
  EXPECT_EQ(a.materials[0].colour.z, b.materials[0].colour.z);
  EXPECT_EQ(a.materials[0].shininess, 32.0); EXPECT_EQ(a.materials[0].brdf, "blinn");
  ASSERT_EQ(a.objects.size(), 1u);
  EXPECT_EQ(a.objects[0].mesh.triangles, b.objects[0].mesh.triangles);
  EXPECT_EQ(projectScene(a).front, 2088u);

  const Scene s = loadScene(kScenes + "/still_life.json");
  ASSERT_EQ(s.objects.size(), 3u);
  EXPECT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[1].kind, Light::Kind::Point);
  EXPECT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.objects[0].source, kScenes + "/icosphere.obj");  // relative to the scene file
  EXPECT_EQ(s.objects[0].mesh.positions.size(), 42u);
  EXPECT_EQ(s.objects[0].mesh.triangles.size(), 80u);
  EXPECT_EQ(s.materials[static_cast<size_t>(s.objects[1].material)].brdf, "schlick");
  for (size_t o = 0; o < 3; ++o) {
    const Projection p = projectScene(s, static_cast<int>(o));
    fmt::print("still_life {}: {} of {} front, {} in the viewport\n", s.objects[o].name, p.front,
               p.triangles, p.front_in_viewport);
    EXPECT_GT(p.front_in_viewport, p.triangles / 4) << s.objects[o].name;
  }
}

TEST(SceneFile, DefaultsRelativeMeshesAndBuiltinSources) {
  TempDir tmp;
  fs::create_directories(tmp.path / "meshes");
  fs::copy_file(kScenes + "/icosphere.obj", tmp.path / "meshes" / "ball.obj");
  const std::string f = tmp.write("sub/../scene.json", R"j({
    "objects": [{"mesh": "meshes/ball.obj"},
                {"mesh": "meshes/ball.obj", "transform": {"translate": [2, 0, 0], "scale": [1, 2, -1]}},
                {"mesh": "builtin:torus"}, {"mesh": "builtin:plane(2, 3, 4)"}, {"mesh": "builtin:sphere(0.5,8)"}]
  })j");
  const Scene s = loadScene(f);
  EXPECT_EQ(s.camera.eye.z, -3.0);
  EXPECT_TRUE(s.lights.empty());
  ASSERT_EQ(s.materials.size(), 1u);  // Material{} for the objects without one
  EXPECT_EQ(s.materials[0].name, "default");
  ASSERT_EQ(s.objects.size(), 5u);
  EXPECT_EQ(s.objects[0].name, "object0");
  EXPECT_EQ(s.objects[0].mesh.triangles.size(), 80u);
  EXPECT_EQ(s.objects[1].transform.determinant3(), -2.0);
  EXPECT_EQ(s.objects[2].mesh.triangles.size(), 2u * 48 * 24);
  EXPECT_EQ(s.objects[3].mesh.triangles.size(), 2u * 4 * 4);
  EXPECT_EQ(s.objects[4].mesh.triangles.size(), static_cast<size_t>(idx3dSphereTriangleCount(8)));
  for (const SceneObject& o : s.objects) EXPECT_EQ(o.material, 0);
  const Vec3 p = s.objects[1].transform.point({1, 1, 1});
  EXPECT_EQ(p.x, 3.0); EXPECT_EQ(p.y, 2.0); EXPECT_EQ(p.z, -1.0);
}

// Each malformed scene gives a SceneError "<file>: <field path>: ..." containing `expect`.
TEST(SceneFile, ErrorsNameTheFileAndTheField) {
  TempDir tmp;
  const std::string ok_material = R"j("materials": [{"name": "m"}])j";
  struct Bad {
    const char* what;
    std::string json;
    std::string expect;  // after "<file>: "
  };
  const std::vector<Bad> cases = {
      {"unknown top-level key", R"j({"objects": [{"mesh": "builtin:sphere"}], "camra": {}})j", "camra: unknown key"},
      {"unknown object key", R"j({"objects": [{"mesh": "builtin:sphere", "colour": [1,0,0]}]})j",
       "objects[0].colour: unknown key"},
      {"unknown camera key", R"j({"camera": {"fov": 60}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.fov: unknown key"},
      {"wrong type", R"j({"camera": {"width": "512"}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.width: expected an integer in 1..4096"},
      {"wrong vector length", R"j({"camera": {"eye": [0, 0]}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.eye: expected an array of 3 numbers"},
      {"wrong element type", R"j({"camera": {"eye": [0, "a", 1]}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.eye[1]: expected a number, got string"},
      {"missing material", "{" + ok_material + R"j(, "objects": [{"mesh": "builtin:sphere"},
                                                              {"mesh": "builtin:sphere", "material": "gold"}]})j",
       "objects[1].material: no material named 'gold'"},
      {"missing mesh file", R"j({"objects": [{"mesh": "nowhere/teapot.obj"}]})j", "objects[0].mesh: "},
      {"shininess 0", R"j({"materials": [{"name": "m", "shininess": 0}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "materials[0].shininess: 0 is out of range [1, 1000]"},
      {"shininess 1001", R"j({"materials": [{"name": "m", "shininess": 1001}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "materials[0].shininess: 1001 is out of range [1, 1000]"},
      {"scale", R"j({"objects": [{"mesh": "builtin:sphere"}, {"mesh": "builtin:sphere"},
                                {"mesh": "builtin:sphere", "transform": {"scale": "big"}}]})j",
       "objects[2].transform.scale: expected a number or an array of 3 numbers"},
      {"zero scale", R"j({"objects": [{"mesh": "builtin:sphere", "transform": {"scale": [1, 0, 1]}}]})j",
       "objects[0].transform.scale: scale factor 0 must have a magnitude in [1e-06, 1000000]"},
      {"huge scale", R"j({"objects": [{"mesh": "builtin:sphere", "transform": {"scale": 1e300}}]})j",
       "objects[0].transform.scale: scale factor 1e+300 must have a magnitude in [1e-06, 1000000]"},
      {"far translation", R"j({"objects": [{"mesh": "builtin:sphere", "transform": {"translate": [0, 2e6, 0]}}]})j",
       "objects[0].transform.translate[1]: 2000000 is out of range [-1000000, 1000000]"},
      {"eye far away", R"j({"camera": {"eye": [0, 0, -1e200]}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.eye[2]: -1e+200 is out of range [-1000000, 1000000]"},
      {"huge px_per_unit", R"j({"camera": {"px_per_unit": 1e300}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.px_per_unit: 1e+300 is out of range [1e-06, 1000000]"},
      {"width too large", R"j({"camera": {"width": 5000}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.width: 5000 is out of range 1..4096"},
      {"height zero", R"j({"camera": {"height": 0}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.height: 0 is out of range 1..4096"},
      {"fractional width", R"j({"camera": {"width": 511.5}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.width: expected an integer"},
      {"negative px_per_unit", R"j({"camera": {"px_per_unit": -1}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.px_per_unit: -1 is out of range [1e-06, 1000000]"},
      {"zero z_near", R"j({"camera": {"z_near": 0}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.z_near: 0 is out of range [1e-06, 1000000]"},
      {"eye at target", R"j({"camera": {"eye": [1,1,1], "target": [1,1,1]}, "objects": [{"mesh": "builtin:sphere"}]})j",
       "camera.target: equals the eye"},
      {"infinite number", R"j({"camera": {"px_per_unit": 1e999}, "objects": [{"mesh": "builtin:sphere"}]})j", ""},
      {"no objects", R"j({"lights": []})j", "objects: missing (required)"},
      {"empty objects", R"j({"objects": []})j", "objects: a scene needs at least one object"},
      {"objects not an array", R"j({"objects": {}})j", "objects: expected an array, got object"},
      {"root not an object", R"j([1, 2])j", "expected an object, got array"},
      {"light type", R"j({"lights": [{"type": "spot"}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "lights[0].type: 'spot' is not a light type"},
      {"light field of the other type",
       R"j({"lights": [{"type": "directional", "direction": [0,1,0], "position": [1,1,1]}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "lights[0].position: unknown key"},
      {"light without direction", R"j({"lights": [{"type": "directional"}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "lights[0].direction: missing (required)"},
      {"zero direction", R"j({"lights": [{"type": "directional", "direction": [0,0,0]}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "lights[0].direction: must not be the zero vector"},
      {"negative light colour", R"j({"lights": [{"type": "point", "position": [0,0,0], "colour": [1,-1,1]}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "lights[0].colour[1]: -1 is out of range"},
      {"colour out of 0..1", R"j({"materials": [{"name": "m", "colour": [0, 2, 0]}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "materials[0].colour[1]: 2 is out of range [0, 1]"},
      {"bad hex colour", R"j({"materials": [{"name": "m", "colour": "#30G0C0"}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "materials[0].colour: '#30G0C0' is not a colour"},
      {"unknown brdf", R"j({"materials": [{"name": "m", "brdf": "ward"}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "materials[0].brdf: 'ward' is not a brdf"},
      {"duplicate material", R"j({"materials": [{"name": "m"}, {"name": "m"}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "materials[1].name: duplicate material name 'm'"},
      {"material without name", R"j({"materials": [{"kd": 1}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "materials[0].name: missing (required)"},
      {"negative kd", R"j({"materials": [{"name": "m", "kd": -0.5}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "materials[0].kd: -0.5 is out of range"},
      {"f0", R"j({"materials": [{"name": "m", "f0": 1.5}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "materials[0].f0: 1.5 is out of range [0, 1]"},
      {"roughness", R"j({"materials": [{"name": "m", "roughness": 0}], "objects": [{"mesh": "builtin:sphere"}]})j",
       "materials[0].roughness: 0 must be > 0"},
      {"unknown builtin mesh", R"j({"objects": [{"mesh": "builtin:cube(1)"}]})j",
       "objects[0].mesh: 'builtin:cube(1)' is not a builtin mesh"},
      {"builtin arity", R"j({"objects": [{"mesh": "builtin:sphere(1)"}]})j",
       "objects[0].mesh: 'builtin:sphere(1)': expected builtin:sphere(radius,segments)"},
      {"builtin argument", R"j({"objects": [{"mesh": "builtin:torus(1,0.3,4.5,8)"}]})j",
       "objects[0].mesh: 'builtin:torus(1,0.3,4.5,8)': argument 3 must be an integer"},
      {"builtin generator rejects", R"j({"objects": [{"mesh": "builtin:torus(1,2,8,8)"}]})j",
       "objects[0].mesh: 'builtin:torus(1,2,8,8)': torusMesh: need 0 < minor radius < major radius"},
      {"builtin not a number", R"j({"objects": [{"mesh": "builtin:plane(1,x,2)"}]})j",
       "objects[0].mesh: 'builtin:plane(1,x,2)': 'x' is not a number"},
      {"mesh not a string", R"j({"objects": [{"mesh": 3}]})j", "objects[0].mesh: expected a string, got number"},
      {"rotate type", R"j({"objects": [{"mesh": "builtin:sphere", "transform": {"rotate_deg": 90}}]})j",
       "objects[0].transform.rotate_deg: expected an array of 3 numbers"},
      {"unknown transform key", R"j({"objects": [{"mesh": "builtin:sphere", "transform": {"rotate": [0,0,0]}}]})j",
       "objects[0].transform.rotate: unknown key"},
  };
  int i = 0;
  for (const Bad& c : cases) {
    const std::string f = tmp.write(fmt::format("bad{}.json", i++), c.json);
    const std::string e = sceneErrorOf(f);
    EXPECT_EQ(e.rfind(f + ": ", 0), 0u) << c.what << ": '" << e << "'";
    EXPECT_NE(e.find(f + ": " + c.expect), std::string::npos) << c.what << ": '" << e << "'";
  }
  // The missing mesh names the mesh file, resolved against the scene file's directory.
  const std::string e = sceneErrorOf(tmp.write("missing.json", R"j({"objects": [{"mesh": "nowhere/teapot.obj"}]})j"));
  EXPECT_NE(e.find((tmp.path / "nowhere/teapot.obj").string() + ": no such file"), std::string::npos) << e;
  // A broken mesh file names the scene, the field and the mesh file with assimp's reason.
  const std::string e2 = sceneErrorOf(
      tmp.write("broken.json", R"j({"objects": [{"mesh": ")j" + kModels + R"j(/invalid/malformed.obj"}]})j"));
  EXPECT_NE(e2.find("objects[0].mesh: " + kModels + "/invalid/malformed.obj: assimp cannot read it: "),
            std::string::npos) << e2;
}

TEST(SceneFile, NotJsonOrMissing) {
  TempDir tmp;
  const std::string f = tmp.write("trunc.json", R"j({"objects": [{"mesh": "builtin:sph)j");
  const std::string e = sceneErrorOf(f);
  EXPECT_EQ(e.rfind(f + ": not valid JSON", 0), 0u) << e;
  EXPECT_EQ(sceneErrorOf("/nonexistent/scene.json"), "/nonexistent/scene.json: no such file");
  // A repeated key would silently keep the last value: an error naming the key.
  const std::string twice = tmp.write("twice.json", R"j({"objects": [{"mesh": "builtin:sphere", "mesh": "x.obj"}]})j");
  EXPECT_EQ(sceneErrorOf(twice), twice + ": key \"mesh\" appears twice in one object");
  // An OFF face naming a vertex past the last, which assimp clamps and only logs.
  const std::string off = tmp.write("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  EXPECT_EQ(sceneErrorOf(off), off + ": assimp reported an error: OFF: Vertex index is out of range");
}

}  // namespace
}  // namespace shd
