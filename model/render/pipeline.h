// The renderer's cold half, shared by every shading method: the frame's buffers, an object's
// vertices in camera space and on the screen, and a mesh triangle's way to the polygon that is
// drawn (back-face culling, the near-plane clip, projection, the guard-band clip). The shading
// methods (render/methods.h) take over from the polygon: render/render.cpp sets up its screen
// triangles and hands each to the method's unit.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/render.h"

namespace shd {

constexpr int kColourFrac = 12;  // colour attributes in LSBs: 0..255 with 12 fraction bits
constexpr int kUnitFrac = 28;    // normals and depth in [-1, 1]
constexpr double kUnitLsb = 1.0 / (1 << kUnitFrac);  // 2^-28: code * kUnitLsb == ldexp(code, -28) exactly
constexpr double kGuard = 2048;  // guard band (px beyond the viewport) before 2D clipping
// The largest projected coordinate the guard-band clipper takes: an intersection it computes
// is off by at most a few ulp of the coordinates, 2^40 * 2^-52 = 1/4096 px, well inside the
// setup's subpixel grid (1/16 px). A vertex beyond it is an error (std::range_error), not a
// silently wrong image.
constexpr double kMaxClipCoord = 1099511627776.0;  // 2^40

// A vertex on its way through the pipeline. cam and n are camera space; colour is the Gouraud
// vertex colour in LSBs (device lobes included).
struct PVertex {
  Vec3 cam{0, 0, 0}, n{0, 0, 1};
  double x = 0, y = 0, w = 0;
  std::array<double, 3> colour{};
};

inline PVertex lerp(const PVertex& a, const PVertex& b, double t) {
  PVertex r;
  r.cam = a.cam + t * (b.cam - a.cam);
  r.n = a.n + t * (b.n - a.n);
  r.x = a.x + t * (b.x - a.x);
  r.y = a.y + t * (b.y - a.y);
  r.w = a.w + t * (b.w - a.w);
  for (size_t k = 0; k < 3; ++k) r.colour[k] = a.colour[k] + t * (b.colour[k] - a.colour[k]);
  return r;
}

// Twice the signed screen area; the idx3d front face has a negative one (y down), see sphere.h.
inline double area2(const PVertex& a, const PVertex& b, const PVertex& c) {
  return (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
}

// A polygon of the clipper: a triangle cut by the near plane and the four guard-band planes
// has at most 3 + 5 vertices.
using Poly = InlineVec<PVertex, 8>;
// The polygon to draw as a fan of screen triangles (fan[0], fan[k], fan[k + 1]): the mesh
// triangle's 3 vertices in the object's vertex array, or the clipped polygon's.
using Fan = InlineVec<const PVertex*, Poly::capacity()>;

// The camera's projection: camera space -> screen (pixels, y down) and w = z_near / Z.
struct Projection {
  double cx = 0, cy = 0, f = 1, z_near = 1;
  explicit Projection(const Camera& cam)
      : cx(0.5 * cam.width), cy(0.5 * cam.height), f(cam.px_per_unit), z_near(cam.z_near) {}
  // For Z >= z_near.
  void project(PVertex& v) const {
    v.x = cx + f * v.cam.x / v.cam.z;
    v.y = cy - f * v.cam.y / v.cam.z;
    v.w = z_near / v.cam.z;
  }
  // Pixel centre -> camera space point of the surface, from w = z_near / Z.
  Vec3 pixelCam(double px, double py, double w) const {
    const double Z = z_near / w;
    return Vec3{(px + 0.5 - cx) * Z / f, -(py + 0.5 - cy) * Z / f, Z};
  }
  // The same at a vertex's screen position (the pixel whose centre it is).
  Vec3 vertexCam(const PVertex& v) const { return pixelCam(v.x - 0.5, v.y - 0.5, v.w); }
};

// The buffers of a W x H frame, cleared, in two steps: prepareClear sizes them (a new size or
// kind cleared whole; lsb and spec_lsb only for an exact method, tri only with tags) and marks
// nothing drawn, and returns what is left to clear: when fb already held a frame of that size
// and kind, the rectangle that frame drew (Framebuffer::markDrawn; the rest is clear), which
// clearRect clears (x0 > x1: nothing). A two-thread frame's back end runs clearRect (render.cpp).
struct ClearRect {
  int x0, y0, x1, y1;
  bool exact;
};
ClearRect prepareClear(Framebuffer& fb, int W, int H, bool exact, bool tags);
void clearRect(Framebuffer& fb, const ClearRect& r);

// Object -> camera space and the projection of the vertices [begin, end) in front of the near
// plane, in an array that holds them all, each one made anew (its colour left to the method,
// render.cpp): an object's vertices, or parts of them on either thread of a two-thread frame.
// Four at a time in AVX2 lanes where the CPU has them (fixed_simd::availableAvx2: not with
// SHD_SCALAR) and vector holds, with the same bits as one at a time. Without normals (a method
// that reads none, MethodTraits::face_colours) each vertex's normal is left 0.
void transformVertexRange(const SceneObject& obj, const CameraBasis& basis, const Camera& cam, const Projection& proj,
                          PVertex* verts, size_t begin, size_t end, bool vector = true, bool normals = true);

// The normals of the vertices of the mesh triangles kept lists (its indices into
// obj.mesh.triangles), each as transformVertexRange computes it with normals (the same bits,
// vector or not), into verts; the other vertices' are left as they are. mark and idx: scratch
// (one entry per vertex). A frame transforms its vertices without normals and then computes
// those of the triangles it draws alone (render.cpp).
void triangleNormals(const SceneObject& obj, const CameraBasis& basis, const std::vector<uint32_t>& kept,
                     PVertex* verts, std::vector<uint8_t>& mark, std::vector<uint32_t>& idx, bool vector = true);
// The normals of the m vertices idx lists, as triangleNormals computes them, into verts.
void vertexNormals(const SceneObject& obj, const CameraBasis& basis, const uint32_t* idx, size_t m, PVertex* verts,
                   bool vector = true);

// Where a mesh triangle goes before it is clipped.
struct TriangleView {
  const PVertex *v0, *v1, *v2;
  bool all_in;  // all three vertices in front of the near plane (so projected)
};
inline TriangleView viewTriangle(const std::vector<PVertex>& verts, const std::array<uint32_t, 3>& tri, double z_near) {
  const PVertex &v0 = verts[tri[0]], &v1 = verts[tri[1]], &v2 = verts[tri[2]];
  return {&v0, &v1, &v2, v0.cam.z >= z_near && v1.cam.z >= z_near && v2.cam.z >= z_near};
}
// Back faces: a triangle wholly in front of the near plane is culled before anything is copied.
inline bool culledEarly(const TriangleView& t) { return t.all_in && !(area2(*t.v0, *t.v1, *t.v2) < 0); }
// The indices of an object's mesh triangles (its vertices transformed) that culledEarly keeps,
// in order, into kept; returns how many it culls.
size_t keptTriangles(const std::vector<PVertex>& verts, const std::vector<std::array<uint32_t, 3>>& tris, double z_near,
                     std::vector<uint32_t>& kept);

// The visible part of a triangle that is not culledEarly as a fan: its own three vertices (the
// common case, nothing copied), or the polygon clipped by the near plane (camera space) and the
// guard band (screen space: attributes interpolate linearly there, as in the span unit), held
// in poly. False when nothing is left (st.culled_outside) or the clipped triangle faces away
// (st.culled_back); st.clipped counts each clip.
bool clipToFan(const TriangleView& t, const Projection& proj, int W, int H, Poly& poly, Fan& fan, RenderStats& st);

}  // namespace shd
