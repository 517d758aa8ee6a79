#include "scene/sphere.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace shd {

namespace {

// Profile node i of idx3d's SPHERE path: (x, y) in the x-y plane, latitude pi (1/2 - i/(s-2)).
// Evaluated from the nearer pole so that the two hemispheres mirror exactly, with the poles,
// the duplicate south pole (i = s-1) and the equator (i = (s-2)/2) exact.
struct ProfileNode {
  double x, y;
};
ProfileNode profileNode(double r, int s, int i) {
  const int last = s - 2;                       // index of the (first) south-pole node
  if (i == 0) return {0.0, r};                  // north pole
  if (i >= last) return {0.0, -r};              // south pole and its duplicate
  if (2 * i == last) return {r, 0.0};           // equator (s even)
  const bool south = 2 * i > last;
  const int k = south ? last - i : i;           // steps from the nearer pole
  const double theta = kPi * k / last;         // angle from that pole
  const double y = r * std::cos(theta);
  return {r * std::sin(theta), south ? -y : y};
}

}  // namespace

Mesh idx3dSphere(double radius, int segments) {
  if (segments < 4)
    throw std::invalid_argument("idx3dSphere: segments must be >= 4, got " +
                                std::to_string(segments));
  if (!(radius > 0.0)) throw std::invalid_argument("idx3dSphere: radius must be > 0");

  const int s = segments;
  const int nodes = s;      // profile nodes (the south pole twice)
  const int columns = s + 1;  // column s closes on column 0
  Mesh m;
  m.positions.reserve(static_cast<size_t>(idx3dSphereVertexCount(s)));
  for (int j = 0; j < columns; ++j) {
    const int jj = j % s;  // column s has column 0's positions exactly
    const double beta = 2.0 * kPi * jj / s;
    const double cb = std::cos(beta), sb = std::sin(beta);
    for (int i = 0; i < nodes; ++i) {
      const ProfileNode p = profileNode(radius, s, i);
      // Rotation about +y by beta: (x, y, 0) -> (x cos beta, y, -x sin beta), idx3d's sweep.
      m.positions.push_back({p.x * cb, p.y, -p.x * sb});
    }
  }

  auto idx = [nodes](int i, int j) { return static_cast<uint32_t>(i + nodes * j); };
  m.triangles.reserve(static_cast<size_t>(idx3dSphereTriangleCount(s)));
  for (int j = 0; j < columns - 1; ++j)
    for (int i = 0; i < nodes - 1; ++i) {
      m.triangles.push_back({idx(i, j), idx(i, j + 1), idx(i + 1, j)});
      m.triangles.push_back({idx(i, j + 1), idx(i + 1, j + 1), idx(i + 1, j)});
    }
  const int seam = columns - 1;
  for (int i = 0; i < nodes - 1; ++i) {
    m.triangles.push_back({idx(i, seam), idx(i, 0), idx(i + 1, seam)});
    m.triangles.push_back({idx(i, 0), idx(i + 1, 0), idx(i + 1, seam)});
  }

  // idx3d's vertex normals: sum of (b - a) x (c - a) over the triangles using the vertex (no
  // triangle lists a vertex twice, so each is counted once, as idx3d's neighbour list does);
  // negated so that they point outward (see the header).
  std::vector<Vec3> sum(m.positions.size(), Vec3{0, 0, 0});
  for (const auto& t : m.triangles) {
    const Vec3 a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
    const Vec3 w = cross(b - a, c - a);
    for (uint32_t v : t) sum[v] += w;
  }
  m.normals.resize(m.positions.size());
  for (size_t v = 0; v < sum.size(); ++v) {
    // Only degenerate triangles use this vertex, so no face defines its normal: radial.
    if (length(sum[v]) == 0.0) {
      m.normals[v] = normalize(m.positions[v]);
      continue;
    }
    m.normals[v] = normalize(-sum[v]);
  }
  return m;
}

CameraBasis cameraBasis(const Camera& cam) {
  const Vec3 forward = normalize(cam.target - cam.eye);
  Vec3 up_world{0, 1, 0};
  // Looking straight up or down: up_world x forward would vanish; any perpendicular will do.
  if (length(cross(up_world, forward)) < 1e-12) up_world = {0, 0, 1};
  const Vec3 right = normalize(cross(up_world, forward));
  const Vec3 up = cross(forward, right);
  return {right, up, forward};
}

std::vector<ScreenTriangle> projectFrontFaces(const Mesh& mesh, const Camera& cam) {
  const CameraBasis basis = cameraBasis(cam);
  const double cx = 0.5 * cam.width, cy = 0.5 * cam.height;
  std::vector<ScreenTriangle> out;
  out.reserve(mesh.triangles.size() / 2);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    ScreenTriangle st{};
    st.id = static_cast<uint32_t>(t);
    bool behind = false;
    for (int k = 0; k < 3; ++k) {
      const uint32_t vi = mesh.triangles[t][static_cast<size_t>(k)];
      const Vec3 pc = toCameraSpace(basis, cam, mesh.positions[vi]);
      if (!(pc.z >= cam.z_near)) {
        behind = true;
        break;
      }
      ScreenVertexPos& sv = st.v[static_cast<size_t>(k)];
      sv.x = cx + cam.px_per_unit * pc.x / pc.z;
      sv.y = cy - cam.px_per_unit * pc.y / pc.z;
      sv.z = pc.z;
      sv.n = toCameraDirection(basis, mesh.normals[vi]);
    }
    if (behind) continue;  // no clipping at this stage: the triangle is dropped whole
    const ScreenVertexPos &a = st.v[0], &b = st.v[1], &c = st.v[2];
    const double area2 = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    if (!(area2 < 0.0)) continue;  // back-facing, edge-on or degenerate
    out.push_back(st);
  }
  return out;
}

}  // namespace shd
