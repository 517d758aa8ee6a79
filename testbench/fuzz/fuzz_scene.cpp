// libFuzzer target: the scene file reader (model/scene/scene.h loadScene on a .json file).
// Input: the file's bytes. Clean rejection: SceneError (the documented one; a std::bad_alloc
// under libFuzzer's -malloc_limit_mb is left to libFuzzer, which reports it as an OOM).
// Properties of an accepted scene (the rules of the file format in scene.h):
//   - at least one object, each with a material index into Scene::materials and a mesh whose
//     triangles index its vertices, one normal per position;
//   - camera width and height in 1..4096, px_per_unit and z_near > 0, eye != target;
//   - every number finite, directional lights unit length.
// Mesh files named by the scene resolve against the scratch directory, where only the input
// itself lives: meshes come from the builtin generators (their arguments capped at 1024
// segments by the reader); a file name fails to load, which is a SceneError as well.
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "fuzz_util.h"
#include "scene/scene.h"

namespace {

using shd::fuzz::finding;

bool finite(shd::Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void checkMesh(const shd::Mesh& m, const std::string& what) {
  if (m.normals.size() != m.positions.size())
    finding(fmt::format("{}: {} normals for {} positions", what, m.normals.size(), m.positions.size()));
  for (const shd::Vec3& p : m.positions)
    if (!finite(p)) finding(what + ": a position is not finite");
  for (const auto& t : m.triangles)
    for (uint32_t i : t)
      if (i >= m.positions.size()) finding(fmt::format("{}: vertex index {} of {}", what, i, m.positions.size()));
}

void checkScene(const shd::Scene& s) {
  const shd::Camera& c = s.camera;
  if (c.width < 1 || c.width > 4096 || c.height < 1 || c.height > 4096)
    finding(fmt::format("camera {}x{} accepted", c.width, c.height));
  if (!(c.px_per_unit > 0) || !(c.z_near > 0) || !finite(c.eye) || !finite(c.target))
    finding("camera with a non-positive or non-finite field accepted");
  if (c.eye.x == c.target.x && c.eye.y == c.target.y && c.eye.z == c.target.z) finding("eye == target accepted");
  if (!finite(s.ambient)) finding("non-finite ambient accepted");
  for (const shd::Light& l : s.lights) {
    if (!finite(l.colour) || !finite(l.position) || !finite(l.direction)) finding("non-finite light accepted");
    if (l.kind == shd::Light::Kind::Directional && std::fabs(shd::length(l.direction) - 1) > 1e-9)
      finding(fmt::format("directional light of length {}", shd::length(l.direction)));
  }
  if (s.objects.empty()) finding("a scene without objects accepted");
  for (size_t i = 0; i < s.objects.size(); ++i) {
    const shd::SceneObject& o = s.objects[i];
    if (o.material < 0 || static_cast<size_t>(o.material) >= s.materials.size())
      finding(fmt::format("objects[{}]: material index {} of {}", i, o.material, s.materials.size()));
    checkMesh(o.mesh, fmt::format("objects[{}] ({})", i, o.source));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = shd::fuzz::writeInput("scene.json", data, size);
  shd::Scene scene;
  try {
    scene = shd::loadScene(path);
  } catch (const shd::SceneError& e) {
    shd::fuzz::rejected(e);
    return 0;
  }
  checkScene(scene);
  return 0;
}
