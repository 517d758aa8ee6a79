// Scenes: transforms, the torus and plane generators, the builtin scenes and the JSON scene
// files (scene/scene.h documents all of it; loadMeshFile is in mesh_io.cpp).
#include "scene/scene.h"
#include "io/files.h"
#include "io/json_strict.h"

#include <cctype>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace shd {

namespace {

// sin and cos of 2 pi k / n, exact where the angle is a multiple of 90 degrees (so a torus
// has exact extreme points and symmetric rings, as idx3dSphere's poles and equator).
void sinCosTurn(int k, int n, double& s, double& c) {
  k %= n;
  if ((4 * k) % n == 0) {
    static constexpr double kS[4] = {0, 1, 0, -1}, kC[4] = {1, 0, -1, 0};
    s = kS[4 * k / n];
    c = kC[4 * k / n];
    return;
  }
  const double a = 2.0 * kPi * k / n;
  s = std::sin(a);
  c = std::cos(a);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Mat4

Mat4 Mat4::translate(Vec3 t) {
  Mat4 r;
  r.m[0][3] = t.x;
  r.m[1][3] = t.y;
  r.m[2][3] = t.z;
  return r;
}

Mat4 Mat4::scale(Vec3 s) {
  Mat4 r;
  r.m[0][0] = s.x;
  r.m[1][1] = s.y;
  r.m[2][2] = s.z;
  return r;
}

Mat4 Mat4::rotateDeg(Vec3 xyz) {
  // Degrees to sin/cos, exact at multiples of 90 degrees (a quarter turn must not leave 6e-17
  // residues that would make axis-aligned faces slightly oblique).
  auto sc = [](double deg, double& s, double& c) {
    const double q = deg / 90.0;
    if (q == std::floor(q) && std::fabs(q) < 1e9) {
      const long k = ((static_cast<long>(q) % 4) + 4) % 4;
      static constexpr double kS[4] = {0, 1, 0, -1}, kC[4] = {1, 0, -1, 0};
      s = kS[k];
      c = kC[k];
      return;
    }
    const double a = deg * kPi / 180.0;
    s = std::sin(a);
    c = std::cos(a);
  };
  double s, c;
  Mat4 rx, ry, rz;
  sc(xyz.x, s, c);
  rx.m[1][1] = c, rx.m[1][2] = -s, rx.m[2][1] = s, rx.m[2][2] = c;
  sc(xyz.y, s, c);
  ry.m[0][0] = c, ry.m[0][2] = s, ry.m[2][0] = -s, ry.m[2][2] = c;
  sc(xyz.z, s, c);
  rz.m[0][0] = c, rz.m[0][1] = -s, rz.m[1][0] = s, rz.m[1][1] = c;
  return rz * ry * rx;
}

Mat4 Mat4::operator*(const Mat4& o) const {
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double acc = 0;
      for (int k = 0; k < 4; ++k) acc += m[i][k] * o.m[k][j];
      r.m[i][j] = acc;
    }
  return r;
}

double Mat4::determinant3() const {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

Vec3 Mat4::normal(Vec3 n) const { return NormalTransform(*this)(n); }

NormalTransform::NormalTransform(const Mat4& t) : mirror(t.determinant3() < 0) {
  // The cofactor matrix is det * inverse transpose: no division, and the sign of det restores
  // the orientation (a mirror must keep outward normals outward).
  const auto& m = t.m;
  c[0][0] = m[1][1] * m[2][2] - m[1][2] * m[2][1];
  c[0][1] = m[1][2] * m[2][0] - m[1][0] * m[2][2];
  c[0][2] = m[1][0] * m[2][1] - m[1][1] * m[2][0];
  c[1][0] = m[0][2] * m[2][1] - m[0][1] * m[2][2];
  c[1][1] = m[0][0] * m[2][2] - m[0][2] * m[2][0];
  c[1][2] = m[0][1] * m[2][0] - m[0][0] * m[2][1];
  c[2][0] = m[0][1] * m[1][2] - m[0][2] * m[1][1];
  c[2][1] = m[0][2] * m[1][0] - m[0][0] * m[1][2];
  c[2][2] = m[0][0] * m[1][1] - m[0][1] * m[1][0];
}

Mesh worldMesh(const SceneObject& obj) {
  Mesh w;
  w.positions.reserve(obj.mesh.positions.size());
  w.normals.reserve(obj.mesh.normals.size());
  for (const Vec3& p : obj.mesh.positions) w.positions.push_back(obj.transform.point(p));
  for (const Vec3& n : obj.mesh.normals) w.normals.push_back(obj.transform.normal(n));
  w.triangles = obj.mesh.triangles;
  if (obj.transform.determinant3() < 0)
    for (auto& t : w.triangles) std::swap(t[1], t[2]);
  return w;
}

// ---------------------------------------------------------------------------------------------
// Generators

Mesh torusMesh(double major_radius, double minor_radius, int major_segments, int minor_segments) {
  if (major_segments < 3 || minor_segments < 3)
    throw std::invalid_argument(fmt::format("torusMesh: segments must be >= 3, got {} and {}",
                                            major_segments, minor_segments));
  if (!(minor_radius > 0.0) || !(major_radius > minor_radius) || !std::isfinite(major_radius))
    throw std::invalid_argument(fmt::format(
        "torusMesh: need 0 < minor radius < major radius, got {} and {}", minor_radius, major_radius));
  const int nu = major_segments, nv = minor_segments;
  Mesh m;
  m.positions.reserve(static_cast<size_t>(nu) * nv);
  m.normals.reserve(static_cast<size_t>(nu) * nv);
  // Vertex (i, j): u = 2 pi i / nu about +y, v = 2 pi j / nv around the tube (v = 0 outside,
  // v = 90 deg on top). n = (cos v cos u, sin v, cos v sin u).
  for (int i = 0; i < nu; ++i) {
    double su, cu;
    sinCosTurn(i, nu, su, cu);
    for (int j = 0; j < nv; ++j) {
      double sv, cv;
      sinCosTurn(j, nv, sv, cv);
      const double ring = major_radius + minor_radius * cv;
      m.positions.push_back({ring * cu, minor_radius * sv, ring * su});
      m.normals.push_back(normalize(Vec3{cv * cu, sv, cv * su}));
    }
  }
  // Winding: dP/du x dP/dv points INTO the tube (at u = v = 0: (0,0,1) x (0,1,0) = -x), so
  // (i,j), (i+1,j), (i,j+1) has (b - a) x (c - a) inward: idx3d's front face (sphere.h).
  auto idx = [nu, nv](int i, int j) { return static_cast<uint32_t>((i % nu) * nv + (j % nv)); };
  m.triangles.reserve(2 * static_cast<size_t>(nu) * nv);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.triangles.push_back({idx(i, j), idx(i + 1, j), idx(i, j + 1)});
      m.triangles.push_back({idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)});
    }
  return m;
}

Mesh planeMesh(double size_x, double size_z, int divisions) {
  if (divisions < 1)
    throw std::invalid_argument(fmt::format("planeMesh: divisions must be >= 1, got {}", divisions));
  if (!(size_x > 0.0) || !(size_z > 0.0) || !std::isfinite(size_x) || !std::isfinite(size_z))
    throw std::invalid_argument(fmt::format("planeMesh: sizes must be > 0, got {} and {}", size_x, size_z));
  const int d = divisions;
  Mesh m;
  // Coordinate of grid line k of d: symmetric about 0 and exact at the ends and the centre.
  auto coord = [d](double size, int k) {
    if (2 * k == d) return 0.0;
    return 2 * k < d ? -size * (0.5 - static_cast<double>(k) / d)
                     : size * (0.5 - static_cast<double>(d - k) / d);
  };
  for (int i = 0; i <= d; ++i)
    for (int j = 0; j <= d; ++j) {
      m.positions.push_back({coord(size_x, i), 0.0, coord(size_z, j)});
      m.normals.push_back({0, 1, 0});
    }
  // (i,j) -> +x -> +z: (1,0,0) x (0,0,1) = -y, inward for the +y face: idx3d's front face.
  auto idx = [d](int i, int j) { return static_cast<uint32_t>(i * (d + 1) + j); };
  for (int i = 0; i < d; ++i)
    for (int j = 0; j < d; ++j) {
      m.triangles.push_back({idx(i, j), idx(i + 1, j), idx(i, j + 1)});
      m.triangles.push_back({idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)});
    }
  return m;
}

// ---------------------------------------------------------------------------------------------
// Builtin scenes

namespace {

Vec3 hexColour(uint32_t rgb) {
  return {((rgb >> 16) & 0xFF) / 255.0, ((rgb >> 8) & 0xFF) / 255.0, (rgb & 0xFF) / 255.0};
}

Light defaultLight() {
  Light l;
  l.direction = normalize(Vec3{-1, 1, -1});
  return l;
}

SceneObject makeObject(std::string name, std::string source, Mesh mesh, int material,
                   Mat4 transform = Mat4{}) {
  SceneObject o;
  o.name = std::move(name);
  o.source = std::move(source);
  o.mesh = std::move(mesh);
  o.material = material;
  o.transform = transform;
  return o;
}

Scene builtinSphere() {
  Scene s;
  s.name = "builtin:sphere";
  s.lights = {defaultLight()};
  s.materials = {Material{}};
  s.objects.push_back(makeObject("sphere", "builtin:sphere(1,64)", idx3dSphere(1, 64), 0));
  return s;
}

Scene builtinPlane() {
  Scene s;
  s.name = "builtin:plane";
  s.camera.eye = {0, 1, -3};
  Light l;
  l.kind = Light::Kind::Point;
  l.position = {0, 0.5, 1.5};
  s.lights = {l};
  Material m;
  m.name = "plane";
  m.colour = hexColour(0x405060);
  m.shininess = 300;
  s.materials = {m};
  s.objects.push_back(makeObject("plane", "builtin:plane(8,8,64)", planeMesh(8, 8, 64), 0,
                             Mat4::translate({0, 0, 1})));
  return s;
}

Scene builtinTorus() {
  Scene s;
  s.name = "builtin:torus";
  s.camera.eye = {0, 2.2, -3.2};
  s.lights = {defaultLight()};
  Material m;
  m.name = "torus";
  m.colour = hexColour(0xC06030);
  s.materials = {m};
  s.objects.push_back(makeObject("torus", "builtin:torus(1,0.4,64,32)", torusMesh(1, 0.4, 64, 32), 0));
  return s;
}

Scene builtinMaterials() {
  Scene s;
  s.name = "builtin:materials";
  s.camera.eye = {0, 0, -10};
  s.camera.px_per_unit = 1024;
  s.lights = {defaultLight()};
  struct Row {
    const char* name;
    uint32_t colour;
    double n;
    const char* brdf;
  };
  static constexpr Row kRows[] = {{"red-phong-1", 0xC03030, 1, "phong"},
                                  {"orange-cubic-8", 0xD08020, 8, "cubic"},
                                  {"blue-blinn-32", 0x3070C0, 32, "blinn"},
                                  {"green-schlick-200", 0x30A050, 200, "schlick"},
                                  {"purple-quadratic-1000", 0x8040B0, 1000, "quadratic"}};
  const Mesh ball = idx3dSphere(0.42, 32);
  int k = 0;
  for (const Row& r : kRows) {
    Material m;
    m.name = r.name;
    m.colour = hexColour(r.colour);
    m.shininess = r.n;
    m.brdf = r.brdf;
    s.materials.push_back(m);
    s.objects.push_back(makeObject(r.name, "builtin:sphere(0.42,32)", ball, k,
                               Mat4::translate({0.95 * (k - 2), 0, 0})));
    ++k;
  }
  return s;
}

}  // namespace

std::vector<std::string> builtinSceneNames() {
  return {"builtin:sphere", "builtin:plane", "builtin:torus", "builtin:materials"};
}

// ---------------------------------------------------------------------------------------------
// JSON scene files

namespace {

using nlohmann::json;

const char* const kBrdfs[] = {"phong",     "blinn", "normalized-blinn", "schlick",
                              "quadratic", "cubic", "cook-torrance",    "pow"};

std::string key(const std::string& path, const std::string& k) {
  return path.empty() ? k : path + "." + k;
}
std::string index(const std::string& path, size_t i) { return fmt::format("{}[{}]", path, i); }

const char* typeName(const json& j) { return j.type_name(); }

// Reads one scene file; every error is "<file>: <field path>: <what>".
class SceneReader {
 public:
  explicit SceneReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    if (path.empty()) throw SceneError(fmt::format("{}: {}", file_, what));
    throw SceneError(fmt::format("{}: {}: {}", file_, path, what));
  }

  const json& object(const json& j, const std::string& path) const {
    if (!j.is_object()) fail(path, fmt::format("expected an object, got {}", typeName(j)));
    return j;
  }
  const json& array(const json& j, const std::string& path) const {
    if (!j.is_array()) fail(path, fmt::format("expected an array, got {}", typeName(j)));
    return j;
  }
  void onlyKeys(const json& j, const std::string& path,
                std::initializer_list<const char*> allowed) const {
    for (auto it = j.begin(); it != j.end(); ++it) {
      bool ok = false;
      for (const char* a : allowed) ok = ok || it.key() == a;
      if (ok) continue;
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      fail(key(path, it.key()), fmt::format("unknown key (expected one of: {})", list));
    }
  }
  const json& required(const json& j, const std::string& path, const char* k) const {
    if (!j.contains(k)) fail(key(path, k), "missing (required)");
    return j.at(k);
  }

  double number(const json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, fmt::format("expected a number, got {}", typeName(j)));
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(path, "expected a finite number");
    return v;
  }
  double numberIn(const json& j, const std::string& path, double lo, double hi) const {
    const double v = number(j, path);
    if (v < lo || v > hi) fail(path, fmt::format("{} is out of range [{}, {}]", v, lo, hi));
    return v;
  }
  double positive(const json& j, const std::string& path) const {
    const double v = number(j, path);
    if (!(v > 0)) fail(path, fmt::format("{} must be > 0", v));
    return v;
  }
  int integerIn(const json& j, const std::string& path, int lo, int hi) const {
    if (!j.is_number() || (j.is_number_float() && j.get<double>() != std::floor(j.get<double>())))
      fail(path, fmt::format("expected an integer in {}..{}", lo, hi));
    const double v = j.get<double>();
    if (v < lo || v > hi) fail(path, fmt::format("{} is out of range {}..{}", v, lo, hi));
    return static_cast<int>(v);
  }
  std::string string(const json& j, const std::string& path) const {
    if (!j.is_string()) fail(path, fmt::format("expected a string, got {}", typeName(j)));
    return j.get<std::string>();
  }
  Vec3 vec3(const json& j, const std::string& path) const {
    if (!j.is_array() || j.size() != 3) fail(path, "expected an array of 3 numbers");
    Vec3 v{number(j[0], index(path, 0)), number(j[1], index(path, 1)), number(j[2], index(path, 2))};
    return v;
  }
  // A point in world space (camera, light, translation): each coordinate within kMaxSceneCoord.
  Vec3 position(const json& j, const std::string& path) const { return vec3Range(j, path, -kMaxSceneCoord, kMaxSceneCoord); }
  Vec3 vec3Range(const json& j, const std::string& path, double lo, double hi) const {
    const Vec3 v = vec3(j, path);
    const double c[3] = {v.x, v.y, v.z};
    for (int i = 0; i < 3; ++i)
      if (c[i] < lo || c[i] > hi) fail(index(path, i), fmt::format("{} is out of range [{}, {}]", c[i], lo, hi));
    return v;
  }
  // "#RRGGBB" or [r, g, b] in 0..1.
  Vec3 materialColour(const json& j, const std::string& path) const {
    if (j.is_string()) {
      const std::string s = j.get<std::string>();
      bool ok = s.size() == 7 && s[0] == '#';
      for (size_t i = 1; ok && i < s.size(); ++i) ok = std::isxdigit(static_cast<unsigned char>(s[i])) != 0;
      if (!ok) fail(path, fmt::format("'{}' is not a colour \"#RRGGBB\"", s));
      return hexColour(static_cast<uint32_t>(std::stoul(s.substr(1), nullptr, 16)));
    }
    if (!j.is_array()) fail(path, "expected \"#RRGGBB\" or an array of 3 numbers in 0..1");
    return vec3Range(j, path, 0.0, 1.0);
  }

  Scene read(const json& root) {
    Scene s;
    s.name = file_;
    object(root, "");
    onlyKeys(root, "", {"camera", "ambient", "lights", "materials", "objects"});
    if (root.contains("camera")) s.camera = camera(root["camera"], "camera");
    if (root.contains("ambient")) s.ambient = vec3Range(root["ambient"], "ambient", 0.0, 1e30);
    if (root.contains("lights")) {
      const json& ls = array(root["lights"], "lights");
      for (size_t i = 0; i < ls.size(); ++i) s.lights.push_back(light(ls[i], index("lights", i)));
    }
    std::map<std::string, int> by_name;
    if (root.contains("materials")) {
      const json& ms = array(root["materials"], "materials");
      for (size_t i = 0; i < ms.size(); ++i) {
        const std::string path = index("materials", i);
        Material m = material(ms[i], path);
        if (!by_name.emplace(m.name, static_cast<int>(s.materials.size())).second)
          fail(key(path, "name"), fmt::format("duplicate material name '{}'", m.name));
        s.materials.push_back(std::move(m));
      }
    }
    const json& os = array(required(root, "", "objects"), "objects");
    if (os.empty()) fail("objects", "a scene needs at least one object");
    for (size_t i = 0; i < os.size(); ++i)
      s.objects.push_back(sceneObject(os[i], index("objects", i), i, s.materials, by_name));
    return s;
  }

 private:
  Camera camera(const json& j, const std::string& path) const {
    object(j, path);
    onlyKeys(j, path, {"eye", "target", "px_per_unit", "width", "height", "z_near"});
    Camera c;
    if (j.contains("eye")) c.eye = position(j["eye"], key(path, "eye"));
    if (j.contains("target")) c.target = position(j["target"], key(path, "target"));
    if (j.contains("px_per_unit"))
      c.px_per_unit = numberIn(j["px_per_unit"], key(path, "px_per_unit"), kMinSceneScale, kMaxSceneScale);
    if (j.contains("width")) c.width = integerIn(j["width"], key(path, "width"), 1, 4096);
    if (j.contains("height")) c.height = integerIn(j["height"], key(path, "height"), 1, 4096);
    if (j.contains("z_near")) c.z_near = numberIn(j["z_near"], key(path, "z_near"), kMinSceneScale, kMaxSceneScale);
    if (!(length(c.target - c.eye) > 0))
      fail(key(path, "target"), "equals the eye (no view direction)");
    return c;
  }

  Light light(const json& j, const std::string& path) const {
    object(j, path);
    const std::string type = string(required(j, path, "type"), key(path, "type"));
    Light l;
    if (type == "directional") {
      onlyKeys(j, path, {"type", "direction", "colour"});
      const Vec3 d = vec3(required(j, path, "direction"), key(path, "direction"));
      if (!(length(d) > 0)) fail(key(path, "direction"), "must not be the zero vector");
      l.kind = Light::Kind::Directional;
      l.direction = normalize(d);
    } else if (type == "point") {
      onlyKeys(j, path, {"type", "position", "colour"});
      l.kind = Light::Kind::Point;
      l.position = position(required(j, path, "position"), key(path, "position"));
    } else {
      fail(key(path, "type"), fmt::format("'{}' is not a light type (directional, point)", type));
    }
    if (j.contains("colour")) l.colour = vec3Range(j["colour"], key(path, "colour"), 0.0, 1e30);
    return l;
  }

  Material material(const json& j, const std::string& path) const {
    object(j, path);
    onlyKeys(j, path, {"name", "colour", "kd", "ks", "shininess", "brdf", "roughness", "f0"});
    Material m;
    m.name = string(required(j, path, "name"), key(path, "name"));
    if (m.name.empty()) fail(key(path, "name"), "must not be empty");
    if (j.contains("colour")) m.colour = materialColour(j["colour"], key(path, "colour"));
    if (j.contains("kd")) m.kd = numberIn(j["kd"], key(path, "kd"), 0, 1e30);
    if (j.contains("ks")) m.ks = numberIn(j["ks"], key(path, "ks"), 0, 1e30);
    if (j.contains("shininess")) m.shininess = numberIn(j["shininess"], key(path, "shininess"), 1, 1000);
    if (j.contains("brdf")) {
      m.brdf = string(j["brdf"], key(path, "brdf"));
      bool ok = false;
      for (const char* b : kBrdfs) ok = ok || m.brdf == b;
      if (!ok)
        fail(key(path, "brdf"), fmt::format("'{}' is not a brdf (phong, blinn, normalized-blinn, "
                                            "schlick, quadratic, cubic, cook-torrance, pow)",
                                            m.brdf));
    }
    if (j.contains("roughness")) m.roughness = positive(j["roughness"], key(path, "roughness"));
    if (j.contains("f0")) m.f0 = numberIn(j["f0"], key(path, "f0"), 0, 1);
    return m;
  }

  Mat4 transform(const json& j, const std::string& path) const {
    object(j, path);
    onlyKeys(j, path, {"translate", "rotate_deg", "scale"});
    Vec3 t{0, 0, 0}, r{0, 0, 0}, sc{1, 1, 1};
    if (j.contains("translate")) t = position(j["translate"], key(path, "translate"));
    if (j.contains("rotate_deg")) r = vec3Range(j["rotate_deg"], key(path, "rotate_deg"), -360, 360);
    if (j.contains("scale")) {
      const json& s = j["scale"];
      const std::string sp = key(path, "scale");
      if (s.is_number()) {
        const double v = number(s, sp);
        sc = {v, v, v};
      } else if (s.is_array() && s.size() == 3) {
        sc = vec3(s, sp);
      } else {
        fail(sp, "expected a number or an array of 3 numbers");
      }
      for (double f : {sc.x, sc.y, sc.z})
        if (!(std::abs(f) >= kMinSceneScale && std::abs(f) <= kMaxSceneScale))
          fail(sp, fmt::format("scale factor {} must have a magnitude in [{}, {}]", f, kMinSceneScale, kMaxSceneScale));
    }
    return Mat4::translate(t) * Mat4::rotateDeg(r) * Mat4::scale(sc);
  }

  // "builtin:<generator>(args)" or a file, relative to the scene file's directory.
  std::pair<Mesh, std::string> mesh(const std::string& src, const std::string& path) {
    static const std::string kPrefix = "builtin:";
    if (src.compare(0, kPrefix.size(), kPrefix) == 0) return {builtinMesh(src, path), src};
    if (src.empty()) fail(path, "empty mesh path");
    std::filesystem::path p(src);
    if (p.is_relative()) p = std::filesystem::path(file_).parent_path() / p;
    const std::string resolved = p.lexically_normal().string();
    auto it = cache_.find(resolved);
    if (it == cache_.end()) {
      try {
        it = cache_.emplace(resolved, loadMeshFile(resolved)).first;
      } catch (const SceneError& e) {
        fail(path, e.what());
      }
    }
    return {it->second, resolved};
  }

  Mesh builtinMesh(const std::string& src, const std::string& path) const {
    const std::string body = src.substr(8);
    const size_t open = body.find('(');
    const std::string gen = body.substr(0, open);
    std::vector<double> args;
    if (open != std::string::npos) {
      if (body.back() != ')') fail(path, fmt::format("'{}': missing ')'", src));
      std::stringstream list(body.substr(open + 1, body.size() - open - 2));
      std::string item;
      while (std::getline(list, item, ',')) {
        const char* b = item.c_str();
        char* e = nullptr;
        const double v = std::strtod(b, &e);
        while (e != nullptr && *e == ' ') ++e;
        if (e == b || *e != '\0' || !std::isfinite(v))
          fail(path, fmt::format("'{}': '{}' is not a number", src, item));
        // Sizes are in the range of a scale factor (the counts are checked below).
        if (!(v >= kMinSceneScale && v <= kMaxSceneScale))
          fail(path, fmt::format("'{}': {} is out of range [{}, {}]", src, v, kMinSceneScale, kMaxSceneScale));
        args.push_back(v);
      }
    }
    auto integer = [&](size_t i, int lo, int hi) {
      const double v = args[i];
      if (v != std::floor(v) || v < lo || v > hi)
        fail(path, fmt::format("'{}': argument {} must be an integer in {}..{}", src, i + 1, lo, hi));
      return static_cast<int>(v);
    };
    auto arity = [&](size_t n, const char* form) {
      if (args.size() != n) fail(path, fmt::format("'{}': expected builtin:{}", src, form));
    };
    try {
      if (gen == "sphere") {
        if (open == std::string::npos) return idx3dSphere(1, 64);
        arity(2, "sphere(radius,segments)");
        return idx3dSphere(args[0], integer(1, 4, 1024));
      }
      if (gen == "torus") {
        if (open == std::string::npos) return torusMesh(1, 0.35, 48, 24);
        arity(4, "torus(major,minor,major_segments,minor_segments)");
        return torusMesh(args[0], args[1], integer(2, 3, 1024), integer(3, 3, 1024));
      }
      if (gen == "plane") {
        if (open == std::string::npos) return planeMesh(4, 4, 16);
        arity(3, "plane(size_x,size_z,divisions)");
        return planeMesh(args[0], args[1], integer(2, 1, 1024));
      }
    } catch (const std::invalid_argument& e) {
      fail(path, fmt::format("'{}': {}", src, e.what()));
    }
    fail(path, fmt::format("'{}' is not a builtin mesh (builtin:sphere(r,seg), "
                           "builtin:torus(R,r,nu,nv), builtin:plane(sx,sz,div))",
                           src));
  }

  SceneObject sceneObject(const json& j, const std::string& path, size_t i,
                          std::vector<Material>& materials, std::map<std::string, int>& by_name) {
    object(j, path);
    onlyKeys(j, path, {"name", "mesh", "material", "transform"});
    SceneObject o;
    o.name = j.contains("name") ? string(j["name"], key(path, "name")) : fmt::format("object{}", i);
    const std::string src = string(required(j, path, "mesh"), key(path, "mesh"));
    std::tie(o.mesh, o.source) = mesh(src, key(path, "mesh"));
    if (j.contains("material")) {
      const std::string name = string(j["material"], key(path, "material"));
      const auto it = by_name.find(name);
      if (it == by_name.end()) fail(key(path, "material"), fmt::format("no material named '{}'", name));
      o.material = it->second;
    } else {
      auto it = by_name.find("default");
      if (it == by_name.end()) {
        it = by_name.emplace("default", static_cast<int>(materials.size())).first;
        materials.push_back(Material{});
      }
      o.material = it->second;
    }
    if (j.contains("transform")) o.transform = transform(j["transform"], key(path, "transform"));
    return o;
  }

  std::string file_;
  std::map<std::string, Mesh> cache_;
};

Scene loadSceneFile(const std::string& file) {
  std::string text;
  try {
    text = readInputFile(file, kMaxSceneFileBytes);
  } catch (const std::runtime_error& e) {
    throw SceneError(e.what());
  }
  json root;
  try {
    root = parseJsonStrict(text);
  } catch (const json::exception& e) {  // parse_error; out_of_range for 1e999
    throw SceneError(fmt::format("{}: not valid JSON: {}", file, e.what()));
  } catch (const std::invalid_argument& e) {  // a repeated key
    throw SceneError(fmt::format("{}: {}", file, e.what()));
  }
  return SceneReader(file).read(root);
}

// A mesh file given as the scene: the default material and light of builtin:sphere, the
// camera on -z looking at the centre of the mesh's bounding box from far enough that its
// bounding sphere fills about 80 % of the 512x512 view.
Scene sceneForMeshFile(const std::string& file) {
  Scene s = builtinSphere();
  s.name = file;
  s.objects.clear();
  SceneObject o;
  o.name = std::filesystem::path(file).stem().string();
  o.source = file;
  o.mesh = loadMeshFile(file);
  Vec3 lo = o.mesh.positions.front(), hi = lo;
  for (const Vec3& p : o.mesh.positions) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const Vec3 centre = 0.5 * (lo + hi);
  const double radius = std::max(1e-9, 0.5 * length(hi - lo));
  // Screen radius of the bounding sphere at distance d: px_per_unit * r / sqrt(d^2 - r^2).
  const double want = 0.4 * s.camera.width;
  const double d = radius * std::sqrt(1 + std::pow(s.camera.px_per_unit / want, 2));
  s.camera.target = centre;
  s.camera.eye = centre - Vec3{0, 0, d};
  s.camera.z_near = std::max(1e-6, 1e-3 * d);
  s.objects.push_back(std::move(o));
  return s;
}

}  // namespace

Scene loadScene(const std::string& spec) {
  if (spec == "builtin:sphere") return builtinSphere();
  if (spec == "builtin:plane") return builtinPlane();
  if (spec == "builtin:torus") return builtinTorus();
  if (spec == "builtin:materials") return builtinMaterials();
  if (spec.compare(0, 8, "builtin:") == 0) {
    std::string names;
    for (const std::string& n : builtinSceneNames()) names += (names.empty() ? "" : ", ") + n;
    throw SceneError(fmt::format("{}: unknown builtin scene (known: {})", spec, names));
  }
  std::string ext = std::filesystem::path(spec).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".json") return sceneForMeshFile(spec);
  return loadSceneFile(spec);
}

}  // namespace shd
