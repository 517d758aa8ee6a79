// builtin:sphere, the idx3d III sphere of the default scene (model/scene/scene.h), and the
// camera that views it: transform, back-face cull and perspective projection to screen space.
//
// ---------------------------------------------------------------------------------------------
// Source followed
//   idx3d III (c) 1999/2000 Peter Walser, as published in github.com/pwalser75/idx3d,
//   idx3d-core/src/main/java/idx3d/idx3d_ObjectFactory.java (SPHERE, ROTATIONOBJECT),
//   idx3d_Object.java (rebuild/regenerate), idx3d_Vertex.java (regenerateNormal),
//   idx3d_Triangle.java (getWeightedNormal, clipFrustrum), idx3d_Vector.java (vectorProduct),
//   idx3d_Camera.java (rebuildMatrices); the copy in AlessandroBorges/IDX3D
//   (source/idx3d/IObjectFactory.java) has the same SPHERE and ROTATIONOBJECT. The construction
//   below is re-derived from that code, not translated line by line.
//
// idx3d's SPHERE(r, s): a profile path of s nodes in the x-y plane, swept about the y axis
//   Path: node i = 0 .. s-2 at latitude phi_i = pi (1/2 - i/(s-2)), i.e. (r cos phi_i, r sin phi_i):
//     node 0 is the north pole, node s-2 the south pole, s-2 equal steps between them; node s-1
//     is the south pole AGAIN (idx3d sets path[s-1] explicitly and its loop also reaches -pi/2 at
//     i = s-2). So a profile has s nodes, one of them a duplicate.
//   Sweep (ROTATIONOBJECT with sides = s): s+1 columns j = 0 .. s, column j is the profile rotated
//     by beta_j = 2 pi j / s about +y as (x, y, 0) -> (x cos beta_j, y, -x sin beta_j). Column s
//     closes the surface on column 0 (same positions, separate vertices: idx3d gives them u = 0
//     and u = 1). Vertex index = i + s*j.
//       vertices  = (s+1) s                          = 65 * 64 = 4160 for s = 64
//   Triangles, in idx3d's order (which is also our triangle id):
//     for j = 0 .. s-1, i = 0 .. s-2:  (i_j, i_j+1, (i+1)_j), (i_j+1, (i+1)_j+1, (i+1)_j)
//     then the closing strip, for i = 0 .. s-2:  (i_s, i_0, (i+1)_s), (i_0, (i+1)_0, (i+1)_s)
//       triangles = 2 s (s-1) + 2 (s-1) = 2 (s^2 - 1)  = 8064 + 126 = 8190 for s = 64
//   Where the count comes from: only s (2s - 6) = 7808 triangles have area. The other 382 are
//   degenerate and kept, as idx3d keeps them:
//     - per column pair 4: at the north pole (0_j, 0_j+1, 1_j) has two coincident corners; at the
//       south pole ((s-3)_j+1, (s-2)_j+1, (s-2)_j) likewise, and both triangles between node s-2
//       and its duplicate s-1 have all three corners on the pole: 4 s = 256;
//     - the closing strip joins column s to column 0, which coincide: 2 (s-1) = 126.
//     So each column pair has 2s - 6 = 122 real triangles: 1 in the north cap, 2 in each of the
//     s-4 = 60 inner bands, 1 in the south cap.
//
// Precision: idx3d evaluates the path in float with pi ~ 3.14159265f and the sweep with
// pi ~ 3.1415926535; it therefore leaves node s-2 4e-8 off the pole and column s 2e-10 off
// column 0. We evaluate in double with the exact pi and make those coincidences exact (poles at
// (0, +-r, 0), column s = column 0, nodes mirror-symmetric about the equator), so every position
// lies on the sphere to the last bits and the degenerate triangles have exactly zero area. The
// topology, vertex order and triangle order are idx3d's.
//
// Vertex normals, as idx3d computes them: a vertex's normal is the normalised sum, over the
// distinct triangles that use it, of (b - a) x (c - a) (the area-weighted face normal,
// idx3d_Triangle.getWeightedNormal). Vertices are not shared across the seam or at the poles, so
// idx3d's normals there are one-sided: a pole vertex of column j gets the normal of its single
// cap triangle (tilted ~pi/(2(s-2)) = 1.45 deg off the axis), a seam vertex only sees the
// triangles on one side (tilted ~pi/s = 2.8 deg). We reproduce that. None of it is visible from
// the default camera: the poles and the seam (azimuth 0, the +x axis) lie at z = 0, behind the
// silhouette circle z = -1/3 seen from (0, 0, -3).
//   Sign: with idx3d's vertex order, (b - a) x (c - a) points INTO the sphere (idx3d's own
//   pipeline expects that: it draws a triangle whose normal points away from the viewer, and
//   its light map assumes n.z > 0 in camera space). We store the NEGATED sum, so Mesh normals
//   point outward, the convention of the shading code (N.L > 0 on the lit side).
//   Vertices all of whose triangles are degenerate have a zero sum: the s+1 duplicate south-pole
//   vertices (node s-1) and the north pole of column 0 (its two neighbours are the seam strip
//   and the north-pole degenerate triangle). No triangle with area uses them; they get the
//   radial normal position / r.
//
// ---------------------------------------------------------------------------------------------
// Camera and projection (the same left-handed frame as idx3d: x right, y up, z into the screen)
//   forward = normalize(target - eye); right = normalize(up_world x forward) with
//   up_world = (0, 1, 0); up = forward x right. A point p has camera coordinates
//   X = right.(p - eye), Y = up.(p - eye), Z = forward.(p - eye) (Z: distance along the view
//   axis), and screen position
//     x_s = width/2  + px_per_unit * X / Z
//     y_s = height/2 - px_per_unit * Y / Z          (pixels, y down)
//   in the raster convention of raster/: pixel (i, j) covers [i, i+1) x [j, j+1), its centre is
//   (i + 0.5, j + 0.5); the optical axis meets the screen at the pixel corner (width/2,
//   height/2). The default camera is at (0, 0, -3) looking at the origin with 512 px per unit at
//   unit depth (a 53.1 deg field of view on 512 px), so X = x, Y = y, Z = z + 3 exactly.
//   If forward is parallel to up_world, up_world = (0, 0, 1) is used instead.
//
// Culling (projectFrontFaces)
//   - behind the camera: a triangle with any vertex at Z < z_near is rejected (no clipping here;
//     z_near = 0.1 is the depth idx3d clamps its projection to);
//   - back faces: with the signed doubled area in screen coordinates (y down)
//       area2 = (x1 - x0)(y2 - y0) - (x2 - x0)(y1 - y0),
//     a triangle is front-facing iff area2 < 0: counter-clockwise as seen on the screen. That is
//     idx3d's front face for this vertex order (equivalently: the outward normal
//     (c - a) x (b - a) points to the eye). area2 = 0 (edge-on and degenerate triangles) is
//     culled. Front faces keep the mesh's vertex order, so they arrive with area2 < 0.
//   Default scene: 2088 of the 8190 triangles are front-facing (27% of the 7808 with area: the
//   cap seen from distance 3 is 1/3 of the sphere's area, but the triangles crowd towards the
//   hidden poles; the share of the (latitude, azimuth) rectangle inside the cap predicts 2057).
//   Their screen bounding box is x in [75.19, 436.81], y in [75.00, 437.00]; the silhouette
//   circle has radius 512 / sqrt(3^2 - 1) = 181.02 px about (256, 256), i.e. [74.98, 437.02].
//   test_sphere checks both.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "scene/vec.h"

namespace shd {

struct Mesh {
  std::vector<Vec3> positions, normals;            // per vertex; normals unit length, outward
  std::vector<std::array<uint32_t, 3>> triangles;  // vertex indices; the index is the triangle id
};

// idx3d_ObjectFactory.SPHERE(radius, segments): see the header comment. segments >= 4 (idx3d
// divides by segments - 2, and with 3 the profile has no ring); radius > 0. Throws
// std::invalid_argument otherwise.
Mesh idx3dSphere(double radius, int segments);

// Number of vertices and triangles idx3dSphere(r, segments) produces.
constexpr int idx3dSphereVertexCount(int segments) { return (segments + 1) * segments; }
constexpr int idx3dSphereTriangleCount(int segments) {
  return 2 * (segments - 1) * (segments + 1);
}

struct Camera {
  Vec3 eye{0, 0, -3};
  Vec3 target{0, 0, 0};
  double px_per_unit = 512;  // screen pixels per camera-space unit at depth Z = 1
  int width = 512, height = 512;
  double z_near = 0.1;  // triangles with a vertex at Z < z_near are rejected
};

// The camera's orthonormal frame (see the header comment).
struct CameraBasis {
  Vec3 right, up, forward;
};
CameraBasis cameraBasis(const Camera& cam);

// Camera-space coordinates (X, Y, Z) of a point, and of a direction (no translation).
// Inline: per vertex of every frame.
inline Vec3 toCameraDirection(const CameraBasis& b, Vec3 d) { return {dot(b.right, d), dot(b.up, d), dot(b.forward, d)}; }
inline Vec3 toCameraSpace(const CameraBasis& b, const Camera& cam, Vec3 p) { return toCameraDirection(b, p - cam.eye); }

struct ScreenVertexPos {
  double x, y;  // pixels, y down; pixel (i, j) covers [i, i+1) x [j, j+1)
  double z;     // camera-space depth Z (distance along the view axis), > 0
  Vec3 n;       // the vertex normal in camera space (unit, outward)
};

struct ScreenTriangle {
  std::array<ScreenVertexPos, 3> v;  // the mesh's vertex order (area2 < 0, see above)
  uint32_t id;                       // index of the triangle in Mesh::triangles
};

// Transform, cull (behind the camera, back faces, zero screen area) and project, in mesh order.
std::vector<ScreenTriangle> projectFrontFaces(const Mesh& mesh, const Camera& cam);

}  // namespace shd
