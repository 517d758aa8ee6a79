// Seeded random screen-space triangles for the span-unit tests: a stream of triangles of every
// size and every awkward shape (TriangleGenerator), and meshes whose neighbouring triangles share
// exactly the same vertex coordinates (makeSharedEdgeMesh, makeFanMesh), so that a fill rule can
// be checked for gaps and double hits.
//
// Coordinates are doubles in pixels, y down, in the raster convention: pixel (i, j) covers
// [i, i+1) x [j, j+1), its centre is (i + 0.5, j + 0.5). Triangle setup (raster/setup.h) turns
// them into fixed point; the generator deliberately produces the values where that is delicate.
//
// ---------------------------------------------------------------------------------------------
// The stream (TriangleGenerator::next): each triangle draws a size class and a shape,
// independently, with the weights of TriGenOptions; its kind() is "<class>/<shape>".
//   Size classes, by area in px^2 (areaRange; the whole stream's mean is below):
//     pixel1  [0.5, 2]         about one pixel
//     small   [2, 10]
//     mesh    [10, 100]        what a tessellated model gives
//     large   [100, 10^4]
//     screen  [W H / 2, 2 W H] at least half the viewport's area; centroid in its middle half
//   Areas are log-uniform within the class (CutPoint/Snapped: before snapping, then retried
//   until the snapped area is in the class again).
//   Shapes:
//     regular    three points with quality 4 sqrt(3) area / sum(edge^2) >= 0.35 (1 = equilateral)
//     sliver     one long edge L and the third vertex at height w over it, aspect L / w
//                log-uniform in [10, 10^4]; orientation uniform (50 %), within 1e-6..1e-2 rad
//                of horizontal (15 %) or vertical (15 %), or the long edge exactly horizontal
//                (10 %) or exactly vertical (10 %). L is capped at min(g, 8192 - max(W, H)),
//                but at least half the viewport, so that the sliver stays in the guard band
//                from anywhere in the viewport; that lowers the aspect of large slivers (to
//                ~1:50 for area 10^4 with the default g) and of screen ones (to ~1:4).
//     cutpoint   all vertices on the integer lattice (pixel corners) or all on the half-integer
//                lattice (pixel centres): every edge delta is an integer, odd or even, so edge
//                midpoints fall on or off pixel centres and corners (the paper's cut points of
//                the 4-way Sierpinski split)
//     zeroarea   exactly zero area: two equal vertices (40 %), three exactly collinear ones on
//                the subpixel lattice, a fifth of them axis-aligned (50 %), or all three equal
//                (10 %); the class sets the length
//     offscreen  a regular triangle whose centroid lies on a viewport edge (75 %) or corner
//                (25 %), so it is partly outside
//     snapped    every vertex snapped to a pixel centre, a subpixel grid point (k / 2^s), a
//                half-subpixel point ((k + 1/2) / 2^s, where rounding to s bits ties) or a mix
//                per coordinate
//   Placement: a triangle that fits in the viewport lies inside it (except offscreen); larger
//   ones have their centroid in the viewport (screen: in its middle half). Every coordinate lies
//   in the guard box [-g, W + g] x [-g, H + g], g = guard_band, and never beyond +-kTriGenMaxCoord.
//   Both windings: v[1] and v[2] are swapped with probability 1/2.
//   Attributes: attribute k of a vertex is uniform in attr_range[k]; 10 % of the values sit
//   exactly on a range end, and 10 % of the triangles are flat (all three vertices equal).
// Measured with the default options (test_trigen, 10^5 triangles, seed 1): mean area 80 px^2
// (per class: pixel1 1.1, small 5.0, mesh 39, large 2.2e3, screen 3.0e5); mean covered pixels
// (pixel centres inside the triangle and the viewport) 57, of which the 1-in-5000 screen
// triangles (1.5e5 pixels each) bring ~20, so it wanders with their count from seed to seed;
// 10^6 triangles take ~0.4 s (a loaded 2-core machine, where mt19937_64 costs 6 ns a draw).
// Placement retries (a triangle that does not fit the guard box, a snapped one that left its
// class) are bounded: after 256 attempts next() throws std::runtime_error, which only a guard
// band too narrow for the screen class can cause (the defaults need ~1.1 attempts).
//
// Meshes (makeSharedEdgeMesh, makeFanMesh): each vertex is computed once and copied into every
// triangle that uses it, so shared edges have bit-identical end points; all triangles of a mesh
// have the same winding, so every interior edge is used exactly twice, in opposite directions.
//   grid: (cols + 1) x (rows + 1) vertices over a rectangle, interior vertices jittered by up to
//     jitter x the cell size, boundary vertices only along the boundary (corners fixed), so the
//     mesh covers the rectangle exactly; a share of the free coordinates snapped to a pixel
//     centre, a pixel corner or a half-subpixel point (kept only if the vertex stays within
//     0.49 cells of its grid position: then the quads stay simple). Each cell is split along a
//     random diagonal, or along the other one where the first would give a non-positive
//     triangle (a non-convex quad).
//   fan: `segments` triangles around a centre, ring vertices at jittered increasing angles and
//     radii in [radius / 2, radius]; closed (the last triangle ends on the first ring vertex).
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace shd {

constexpr int kTriGenMaxAttr = 8;
constexpr double kTriGenMaxCoord = 8192.0;  // |x|, |y| never exceed this

enum class SizeClass : uint8_t { Pixel1, Small, Mesh, Large, Screen };
constexpr int kNumSizeClasses = 5;

// The first kNumStreamShapes are what TriangleGenerator draws; the mesh builders tag theirs.
enum class TriShape : uint8_t { Regular, Sliver, CutPoint, ZeroArea, OffScreen, Snapped, MeshGrid, MeshFan };
constexpr int kNumStreamShapes = 6;

const char* toString(SizeClass c);  // "pixel1", "small", "mesh", "large", "screen"
const char* toString(TriShape s);   // "regular", "sliver", ..., "meshgrid", "meshfan"

struct GenVertex {
  double x, y;                                // pixels, y down
  std::array<double, kTriGenMaxAttr> attr{};  // the first TriGenOptions::num_attr are used
};

struct GenTriangle {
  std::array<GenVertex, 3> v;
  uint32_t id;
  SizeClass size;  // the class drawn (mesh triangles: classifyArea of their area)
  TriShape shape;
  std::string kind() const;  // "pixel1/regular", "large/sliver", ...
};

struct AttrRange {
  double lo, hi;
};

struct TriGenOptions {
  int width = 512, height = 512;  // viewport W x H
  int subpixel_bits = 4;          // s: the grid the snapped shapes use
  int num_attr = 4;               // attributes per vertex, 0 .. kTriGenMaxAttr
  // Colour 0..255 for attributes 0..2, depth 0..1 for attribute 3, 0..1 for the rest.
  std::array<AttrRange, kTriGenMaxAttr> attr_range{
      {{0, 255}, {0, 255}, {0, 255}, {0, 1}, {0, 1}, {0, 1}, {0, 1}, {0, 1}}};
  double guard_band = 1024;  // g, px beyond each viewport edge that vertices may reach
  // Shares of the stream, by SizeClass and by shape (the first kNumStreamShapes TriShapes);
  // any non-negative weights, normalised by their sum.
  std::array<double, kNumSizeClasses> size_weight{0.25, 0.30, 0.4398, 0.01, 0.0002};
  std::array<double, kNumStreamShapes> shape_weight{0.30, 0.20, 0.15, 0.05, 0.10, 0.20};
};

struct AreaRange {
  double lo, hi;
};
AreaRange areaRange(SizeClass c, const TriGenOptions& opt);  // closed range, px^2
// The class whose range holds `area` (below 2: pixel1; between 10^4 and W H / 2: large).
SizeClass classifyArea(double area, const TriGenOptions& opt);

// The guard box [-g, W + g] x [-g, H + g], clamped to +-kTriGenMaxCoord.
struct Box {
  double x0, y0, x1, y1;
};
Box guardBox(const TriGenOptions& opt);

// Twice the signed area in screen coordinates (y down): > 0 for clockwise on screen.
double signedArea2(const GenTriangle& t);

class TriangleGenerator {
 public:
  // Throws std::invalid_argument on an impossible configuration (viewport < 1 px, num_attr
  // out of range, negative or all-zero weights, a guard band < 0).
  TriangleGenerator(uint64_t seed, const TriGenOptions& opt = {});
  GenTriangle next();
  const TriGenOptions& options() const { return opt_; }

 private:
  std::mt19937_64 rng_;
  TriGenOptions opt_;
  double size_total_ = 0, shape_total_ = 0;  // sums of the weights
  uint32_t next_id_ = 0;
};

struct MeshGenOptions {
  // Grid: the rectangle [x0, x1] x [y0, y1]; an empty one (x1 <= x0 or y1 <= y0) means the
  // viewport. It must lie in the guard box.
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  double jitter = 0.3;      // < 0.5: displacement of interior vertices, in cells
  double snap_share = 0.3;  // share of free coordinates snapped (see the header comment)
  int winding = 0;          // +1: signedArea2 > 0 for every triangle; -1: < 0; 0: random
  uint32_t first_id = 0;    // ids are first_id, first_id + 1, ...
};

// A jittered grid of cols x rows cells, 2 cols rows triangles covering the rectangle exactly.
// Throws std::invalid_argument if cols or rows < 1, jitter is outside [0, 0.5), or the region
// leaves the guard box.
std::vector<GenTriangle> makeSharedEdgeMesh(std::mt19937_64& rng, const TriGenOptions& opt,
                                            int cols, int rows, const MeshGenOptions& mopt = {});

// A closed fan of `segments` >= 3 triangles around (cx, cy) (uses snap_share, winding,
// first_id and jitter, the latter in angular steps). Throws std::invalid_argument if the fan
// leaves the guard box or segments < 3.
std::vector<GenTriangle> makeFanMesh(std::mt19937_64& rng, const TriGenOptions& opt, double cx,
                                     double cy, double radius, int segments,
                                     const MeshGenOptions& mopt = {});

}  // namespace shd
