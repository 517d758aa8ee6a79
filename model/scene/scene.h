// Scenes: meshes with transforms, materials, lights, the camera and the viewport, from a JSON
// scene file (meshes loaded through assimp) or built in.
//
// Scene file (JSON; unknown keys and wrong types are errors naming the file and the field):
//   {
//     "camera":    {"eye": [0,0,-3], "target": [0,0,0], "px_per_unit": 512,
//                   "width": 512, "height": 512, "z_near": 0.1},
//     "ambient":   [0.0, 0.0, 0.0],
//     "lights":    [{"type": "directional", "direction": [-1, 1, -1], "colour": [1,1,1]},
//                   {"type": "point", "position": [2, 2, -2], "colour": [1,1,1]}],
//     "materials": [{"name": "blue", "colour": "#3070C0" or [r,g,b] in 0..1,
//                    "kd": 1.0, "ks": 1.0, "shininess": 32, "brdf": "blinn",
//                    "roughness": 0.3, "f0": 0.04}],
//     "objects":   [{"name": "teapot", "mesh": "teapot.dae" (relative to the scene file) or
//                    "builtin:sphere(1,64)" | "builtin:torus(1,0.35,48,24)" | "builtin:plane(4,4,16)",
//                    "material": "blue",
//                    "transform": {"translate": [0,0,0], "rotate_deg": [0,0,0] (x, then y,
//                                  then z), "scale": 1 or [sx,sy,sz]}}]
//   }
// A directional light's "direction" points from the surface toward the light (it is
// normalised on load). brdf: phong | blinn | normalized-blinn | schlick | quadratic | cubic |
// cook-torrance | pow (the method decides how it is evaluated).
//
// Rules of the file format (every violation is a SceneError "<file>: <field path>: <what>",
// e.g. "scenes/x.json: objects[2].transform.scale: expected a number or an array of 3 numbers"):
//   - "objects" is required and non-empty; every other top-level key is optional.
//   - camera: each field optional (the defaults are Camera's, i.e. the default scene's);
//     width, height integers in 1..4096; px_per_unit and z_near in [1e-6, 1e6]; eye != target.
//   - positions (camera eye and target, point lights, translations): each coordinate within
//     +-1e6 (kMaxSceneCoord); rotate_deg within +-360; scale factors of magnitude [1e-6, 1e6],
//     and the sizes of builtin meshes in [1e-6, 1e6].
//     Inside these limits double precision resolves a position to 1e-10 units, far below a
//     pixel; a projection that still leaves the clipper's exact range is refused by the
//     renderer (render/pipeline.h, kMaxClipCoord).
//   - ambient and light colours: 3 numbers >= 0 (above 1 is a brighter light); material colours
//     in 0..1, or "#RRGGBB" (the hex digits / 255, taken as linear like Material's default).
//   - lights: "type" is required; a directional light needs a non-zero "direction", a point
//     light a "position"; the other type's field is an unknown key. "lights" may be empty.
//   - materials: "name" required, non-empty, unique; kd, ks >= 0; shininess in [1, 1000];
//     brdf one of the names above; roughness > 0; f0 in [0, 1]. Omitted fields take
//     Material's defaults.
//   - objects: "mesh" required; "name" defaults to "object<i>"; "material" names a material of
//     the file; without it the object uses the material named "default" (the file's, or else
//     Material{} appended to Scene::materials). transform: every field optional; a negative
//     scale factor mirrors (worldMesh keeps front faces front).
//   - builtin mesh sources: "builtin:sphere(radius,segments)" = idx3dSphere, "builtin:torus(
//     major,minor,major_segments,minor_segments)" = torusMesh, "builtin:plane(size_x,size_z,
//     divisions)" = planeMesh; without the parenthesis the defaults sphere(1,64),
//     torus(1,0.35,48,24), plane(4,4,16). Segments/divisions are integers, at most 1024.
//   - every number must be finite (JSON has no NaN or infinity; an overflowing literal such as
//     1e999 is reported as "not valid JSON").
//   The same mesh file named by several objects is loaded once.
//
// Transforms: world = translate * rotate * scale * object, rotate = Rz * Ry * Rx (x first),
// each the usual matrix acting on column vectors, e.g. Rx(a) = [1 0 0; 0 c -s; 0 s c]. In
// shadesim's left-handed frame (x right, y up, z into the screen, sphere.h) a positive angle
// about y turns +z toward +x.
//
// Handedness of mesh files: assimp delivers right-handed data with counter-clockwise front
// faces, i.e. outward normal = (b - a) x (c - a). Shadesim's frame is left-handed with the
// outward normal = (c - a) x (b - a) (idx3d's winding, sphere.h). loadMeshFile therefore
// mirrors z (positions and normals) and keeps the vertex order: the mirror turns the winding
// rule of one frame into the other's, and the model looks as in its authoring tool (a
// right-handed viewer looking down -z shows the same image as shadesim's camera looking down
// +z at the mirrored model). A model authored facing +z faces the default camera.
//
// Builtin scenes (loadScene("builtin:<name>"); builtinSceneNames() lists them):
//   sphere     the default scene (the idx3d III sphere the paper's software was built on): idx3dSphere(1, 64), Camera{} (eye (0,0,-3), target
//              origin, 512 px per unit, 512x512, z_near 0.1), one white directional light with
//              direction (-1, 1, -1)/sqrt 3 ("toward the upper left front": -x is left, +y up,
//              -z is toward the viewer), material Material{} (0x3070C0, kd 1, ks 1, n 32,
//              blinn), ambient 0.
//   plane      the paper's flat-surface case (Fig. 4 c, d): planeMesh(8, 8, 64) translated to
//              z in [-3, 5] (8192 triangles; nothing behind the eye), camera eye (0, 1, -3)
//              looking at the origin (18.4 deg below the horizon), one white point light at
//              (0, 0.5, 1.5), low over the plane beyond the origin; material 0x405060, kd 1,
//              ks 1, n 300, blinn. Why a point light: with the renderer's infinite viewer
//              (V = the camera's backward axis, render/shading.h) a directional light gives
//              every point of a plane the same N.H and R.V, i.e. no highlight shape at all; a
//              point light's L varies. It sits where the mirror direction of V at the origin
//              points, so the highlight peaks at the image centre with the light 18.4 deg above
//              the surface (71.6 deg from the normal: grazing). There, lobe > 0.1 covers for
//              Blinn a streak 114 x 286 px running from the centre (y 226) to the bottom edge,
//              for Phong a compact spot 76 x 92 px (test_scene measures it per pixel): the
//              elongated Blinn highlight of the paper. n = 300 keeps Phong's spot and the
//              streak's width well inside the image; the diffuse term is dim (N.L ~ 0.3 at the
//              peak), so the highlight dominates.
//   torus      torusMesh(1, 0.4, 64, 32) in the x-z plane, camera eye (0, 2.2, -3.2) looking at
//              the origin (34.5 deg from above: the hole is visible), the default light,
//              material 0xC06030, n 32, blinn.
//   materials  five idx3dSphere(0.42, 32) in a row, centres x = -1.9 .. 1.9 (step 0.95),
//              camera eye (0, 0, -10), 1024 px per unit (little perspective distortion), the
//              default light; shininess 1, 8, 32, 200, 1000 with brdf phong, cubic, blinn,
//              schlick, quadratic and colours red, orange, blue (0x3070C0), green, purple.
//              (The cubic device holds n <= 256, the quadratic one n <= 1000.)
//   Front faces (projectFrontFaces of every object's worldMesh, test_scene): sphere 2088 of
//   8190; plane 8192 of 8192 (seen from above; 4269 touch the viewport, the rest reach into
//   the guard band); torus 1872 of 4096; materials 4336 of 10230. All but the plane's lie
//   wholly inside the 512x512 viewport.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "scene/sphere.h"
#include "scene/vec.h"

namespace shd {

// Row-major affine transform.
struct Mat4 {
  double m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
  static Mat4 translate(Vec3 t);
  static Mat4 scale(Vec3 s);
  static Mat4 rotateDeg(Vec3 xyz);  // rotation about x, then y, then z
  Mat4 operator*(const Mat4& o) const;
  // Inline (per vertex of every frame).
  Vec3 point(Vec3 p) const { return direction(p) + Vec3{m[0][3], m[1][3], m[2][3]}; }
  Vec3 direction(Vec3 d) const {  // no translation
    return {m[0][0] * d.x + m[0][1] * d.y + m[0][2] * d.z, m[1][0] * d.x + m[1][1] * d.y + m[1][2] * d.z,
            m[2][0] * d.x + m[2][1] * d.y + m[2][2] * d.z};
  }
  Vec3 normal(Vec3 n) const;     // by the inverse transpose, normalised
  double determinant3() const;   // of the linear (upper-left 3x3) part; < 0 mirrors
};

// Mat4::normal for many normals: the cofactor matrix (det times the inverse transpose) and the
// sign of det computed once; operator() equals Mat4::normal bit for bit.
struct NormalTransform {
  explicit NormalTransform(const Mat4& t);
  Vec3 operator()(Vec3 n) const {
    const Vec3 r{c[0][0] * n.x + c[0][1] * n.y + c[0][2] * n.z, c[1][0] * n.x + c[1][1] * n.y + c[1][2] * n.z,
                 c[2][0] * n.x + c[2][1] * n.y + c[2][2] * n.z};
    return normalize(mirror ? -r : r);
  }
  double c[3][3];
  bool mirror;  // det < 0
};

struct Material {
  std::string name = "default";
  Vec3 colour{0x30 / 255.0, 0x70 / 255.0, 0xC0 / 255.0};  // base colour, linear 0..1
  double kd = 1.0, ks = 1.0;
  double shininess = 32;  // n in [1, 1000]
  std::string brdf = "blinn";
  double roughness = 0.3, f0 = 0.04;  // cook-torrance
};

struct Light {
  enum class Kind { Directional, Point };
  Kind kind = Kind::Directional;
  Vec3 direction{-1, 1, -1};  // directional: toward the light, unit length
  Vec3 position{0, 0, 0};     // point
  Vec3 colour{1, 1, 1};
};

struct SceneObject {
  std::string name;
  std::string source;  // the mesh file or builtin generator it came from
  Mesh mesh;           // object space
  Mat4 transform;      // object -> world
  int material = 0;    // index into Scene::materials
};

struct Scene {
  std::string name;  // "builtin:sphere" or the file path
  Camera camera;
  Vec3 ambient{0, 0, 0};
  std::vector<Light> lights;
  std::vector<Material> materials;
  std::vector<SceneObject> objects;
};

// The limits of a scene file's values (above).
constexpr double kMaxSceneCoord = 1e6;
constexpr double kMinSceneScale = 1e-6, kMaxSceneScale = 1e6;
// The largest scene file and mesh file read (a scene file is a few kB; meshes are imported in a
// child process with a memory limit of their own, loadMeshFile).
constexpr uint64_t kMaxSceneFileBytes = uint64_t{16} << 20;
constexpr uint64_t kMaxMeshFileBytes = uint64_t{1} << 30;

// A clear error naming the file (or builtin) and the field.
struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// Throws SceneError "<path>: <what>" (a mesh file's errors).
[[noreturn]] void failMeshFile(const std::string& path, const std::string& what);

// "builtin:sphere", "builtin:plane", "builtin:torus", "builtin:materials", a JSON scene file, or
// a mesh file of any format assimp reads (e.g. teapots.DAE): then the mesh alone, with
// builtin:sphere's material and light, and the camera on -z framing its bounding sphere.
Scene loadScene(const std::string& spec);
// The builtin specs, with the prefix: {"builtin:sphere", "builtin:plane", "builtin:torus",
// "builtin:materials"}.
std::vector<std::string> builtinSceneNames();

// An object's mesh in world space: positions by transform.point, normals by transform.normal;
// a mirroring transform (determinant3 < 0) also swaps two vertices of every triangle, so the
// winding rule (sphere.h) still holds. The identity transform returns the mesh unchanged.
Mesh worldMesh(const SceneObject& obj);

// All meshes of a file through assimp (triangulated, identical vertices joined, smooth normals
// generated where the file has none), in one Mesh. SceneError for a missing, empty, truncated or
// unsupported file, NaN/infinite coordinates or zero-length normals (named with the file).
// Details:
//   - every error reads "<path>: <what>"; assimp's own error string follows "assimp cannot
//     read it: ";
//   - node transforms are applied (PreTransformVertices) and every mesh is merged, in file
//     order; points and lines are dropped; z is mirrored (see "Handedness" above);
//   - triangles with zero area are dropped, then the vertices no triangle uses (neither can be
//     drawn); a file left without triangles is an error;
//   - normals are normalised. A missing, non-finite or zero-length one (assimp leaves NaN at
//     vertices of degenerate faces) is replaced by the normalised area-weighted sum of the
//     vertex's outward face normals; if that sum is zero as well (faces that cancel, as a
//     two-sided sheet), SceneError. A normal pointing against that sum is negated: the
//     winding decides the outside, as it does for culling (assimp-testmodels' STL spiders have
//     an outward winding and inward facet normals). One perpendicular to it (|cos| <= 1e-9,
//     where rounding decides the sign) is replaced as a missing one; where the sum is zero the
//     normal stays. A file wound inside out throughout loads inside out (OFF/Wuson.off);
//   - truncated files: the faces of the plain import are checked before post-processing (a
//     truncated ASCII PLY leaves faces without indices, on which Debian's assimp 5.2 aborts
//     in an assertion instead of failing), and a PLY header without end_header, or with no
//     line break after it, is refused up front (assimp 5.2 loops forever on either). A text
//     file cut at a line boundary is a valid smaller file and loads;
//   - resource limits: the import runs in a child process (mesh_child.cpp) with 4 GB of
//     memory (address space beyond the parent's, and resident memory) and 120 s of wall time.
//     assimp 5.2 terminates on some truncated COB files (an exception thrown where it cannot be
//     caught) and allocates what a header declares (invalid/OutOfMemory.off: 353535235358
//     vertices in 309 bytes): each is a SceneError naming the file and the limit or the
//     signal, and shadesim goes on.
Mesh loadMeshFile(const std::string& path);
// The same import in the calling process, without the limits (the fuzz target's entry; a
// program reads meshes through loadMeshFile). It does not record the file as an input.
Mesh importMeshInProcess(const std::string& path);

// A torus about the y axis: centre circle of radius major_radius in the x-z plane, tube radius
// minor_radius (0 < minor < major). major_segments x minor_segments vertices (shared, no seam
// duplicates), 2 * major_segments * minor_segments triangles; exact positions (angles at
// multiples of 90 deg exact) and analytic unit normals; idx3d's winding. Segments >= 3.
// Throws std::invalid_argument otherwise.
Mesh torusMesh(double major_radius, double minor_radius, int major_segments, int minor_segments);
// A size_x by size_z grid centred on the origin in y = 0, normal +y, front face seen from +y:
// (divisions + 1)^2 vertices, 2 divisions^2 triangles. Sizes > 0, divisions >= 1, else
// std::invalid_argument.
Mesh planeMesh(double size_x, double size_z, int divisions);  // in y = 0, normal +y

}  // namespace shd
