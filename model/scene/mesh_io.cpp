// importMeshInProcess: mesh files through assimp 5.2 (the policy is documented in
// scene/scene.h; loadMeshFile runs it in a child process, mesh_child.cpp).
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cctype>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "io/files.h"
#include "scene/scene.h"

namespace shd {

void failMeshFile(const std::string& path, const std::string& what) {
  throw SceneError(fmt::format("{}: {}", path, what));
}

namespace {

bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The outward face normal in shadesim's convention, area-weighted: (c - a) x (b - a) (see
// scene.h, "Handedness"; sphere.h for the winding).
Vec3 outwardAreaNormal(const Mesh& m, const std::array<uint32_t, 3>& t) {
  const Vec3 a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
  return cross(c - a, b - a);
}

// assimp 5.2's PLY reader loops forever on a header without "end_header" (a file cut inside its
// header), and on one whose "end_header" is the file's last bytes (a file cut right after it:
// fuzz_mesh, corpus file finding-ply-end-header-at-end-of-file): refuse such a file before assimp
// sees it, as a header whose last line has no line break. assimp takes a file as PLY when it
// starts with "ply" in any case and any fourth byte (test fuzz_replay_mesh keeps "ply " and "plY").
void checkPlyHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[4] = {};
  in.read(magic, 4);
  auto lower = [](char ch) { return static_cast<char>(std::tolower(static_cast<unsigned char>(ch))); };
  if (in.gcount() < 4 || lower(magic[0]) != 'p' || lower(magic[1]) != 'l' || lower(magic[2]) != 'y') return;
  // The header is ASCII lines; real headers are a few hundred bytes, comments included.
  std::string line;
  for (int lines = 0; lines < 10000 && std::getline(in, line); ++lines) {
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    if (line == "end_header") {
      if (in.eof()) failMeshFile(path, "PLY header without a line break after end_header (truncated file)");
      return;
    }
  }
  failMeshFile(path, "PLY header without end_header (truncated file)");
}

// Faces of the plain import that post-processing cannot take: no indices, or an index past
// the mesh's vertices (both left by truncated files).
void checkFaces(const std::string& path, const aiScene* scene) {
  for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
    const aiMesh* am = scene->mMeshes[k];
    if (am->mNumVertices > 0 && am->mVertices == nullptr) failMeshFile(path, fmt::format("mesh {} has no positions", k));
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices == 0 || face.mIndices == nullptr)
        failMeshFile(path, fmt::format("mesh {} face {} has no vertex indices (truncated or malformed file)", k, f));
      for (unsigned i = 0; i < face.mNumIndices; ++i)
        if (face.mIndices[i] >= am->mNumVertices)
          failMeshFile(path, fmt::format("mesh {} face {}: vertex index {} out of range (the mesh has {} "
                                 "vertices; truncated or malformed file)",
                                 k, f, face.mIndices[i], am->mNumVertices));
    }
  }
}

// assimp reports some malformed input only in its log and goes on with a repaired guess (an OFF
// face naming a vertex past the last is clamped to the last vertex, "OFF: Vertex index is out of
// range"). Its error messages are collected while a file is imported; one about an index out of
// range fails the import, since the geometry is no longer the file's. (Its other errors are
// about what shadesim does not read, such as unsupported chunks or missing materials.)
class ErrorLog final : public Assimp::LogStream {
 public:
  explicit ErrorLog(std::vector<std::string>& out) : out_(out) {}
  void write(const char* message) override {
    std::string m(message);
    while (!m.empty() && (m.back() == '\n' || m.back() == '\r')) m.pop_back();
    const size_t colon = m.find(": ");  // "Error, T0: <text>"
    out_.push_back(colon == std::string::npos ? m : m.substr(colon + 2));
  }

 private:
  std::vector<std::string>& out_;
};

struct AssimpErrors {
  std::vector<std::string> messages;
  AssimpErrors() {
    Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);
    Assimp::DefaultLogger::get()->attachStream(new ErrorLog(messages), Assimp::Logger::Err);  // the logger owns it
  }
  ~AssimpErrors() { Assimp::DefaultLogger::kill(); }
  AssimpErrors(const AssimpErrors&) = delete;
  AssimpErrors& operator=(const AssimpErrors&) = delete;
};

}  // namespace

Mesh importMeshInProcess(const std::string& path) {
  if (const std::string why = inputFileProblem(path, kMaxMeshFileBytes); !why.empty()) failMeshFile(path, why);
  checkPlyHeader(path);

  // Two stages: the plain import, a check of its faces, then the post-processing. Merging
  // every mesh into one needs the node transforms applied (PreTransformVertices). The check
  // comes first because Debian's assimp 5.2 is built with its assertions on and aborts the
  // process in TriangulateProcess on the faces a truncated ASCII PLY leaves (faces with no
  // indices), instead of reporting an error.
  constexpr unsigned kPostFlags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                  aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices;
  const AssimpErrors log;
  Assimp::Importer importer;
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
    for (const std::string& m : log.messages)
      if (scene != nullptr && m.find("out of range") != std::string::npos)
        failMeshFile(path, fmt::format("assimp reported an error: {}", m));
    if (scene != nullptr) {
      checkFaces(path, scene);
      scene = importer.ApplyPostProcessing(kPostFlags);
    }
  } catch (const SceneError&) {
    throw;
  } catch (const std::exception& e) {  // assimp reports through the error string; be safe
    failMeshFile(path, fmt::format("assimp cannot read it: {}", e.what()));
  }
  if (scene == nullptr) failMeshFile(path, fmt::format("assimp cannot read it: {}", importer.GetErrorString()));
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || scene->mNumMeshes == 0)
    failMeshFile(path, "no triangles (the file has no meshes)");

  // Merge: every mesh's vertices, then its triangles (points and lines are skipped), with
  // z mirrored from assimp's right-handed frame into shadesim's left-handed one (scene.h).
  Mesh raw;
  for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
    const aiMesh* am = scene->mMeshes[k];
    const size_t base = raw.positions.size();
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      const Vec3 pos{p.x, p.y, -static_cast<double>(p.z)};
      if (!finite(pos))
        failMeshFile(path, fmt::format("mesh {} vertex {}: position ({}, {}, {}) is not finite", k, v, p.x,
                               p.y, p.z));
      raw.positions.push_back(pos);
      // NaN marks "none" (assimp leaves NaN for vertices of degenerate faces); fixed below.
      if (am->mNormals != nullptr) {
        const aiVector3D& n = am->mNormals[v];
        raw.normals.push_back({n.x, n.y, -static_cast<double>(n.z)});
      } else {
        raw.normals.push_back({NAN, NAN, NAN});
      }
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;  // a point or a line: nothing to shade
      std::array<uint32_t, 3> t{};
      for (int i = 0; i < 3; ++i) t[i] = static_cast<uint32_t>(base + face.mIndices[i]);
      raw.triangles.push_back(t);
    }
  }
  if (raw.triangles.empty()) failMeshFile(path, "no triangles (only points or lines)");

  // Drop the triangles without area and then the vertices no triangle uses: neither can ever
  // be drawn (a degenerate triangle projects to a segment), and afterwards every vertex has a
  // triangle with a defined face normal.
  Mesh m;
  std::vector<uint32_t> remap(raw.positions.size(), UINT32_MAX);
  for (const auto& t : raw.triangles) {
    const Vec3 w = outwardAreaNormal(raw, t);
    if (!(length(w) > 0.0)) continue;
    std::array<uint32_t, 3> nt{};
    for (int i = 0; i < 3; ++i) {
      uint32_t& r = remap[t[i]];
      if (r == UINT32_MAX) {
        r = static_cast<uint32_t>(m.positions.size());
        m.positions.push_back(raw.positions[t[i]]);
        m.normals.push_back(raw.normals[t[i]]);
      }
      nt[i] = r;
    }
    m.triangles.push_back(nt);
  }
  if (m.triangles.empty()) failMeshFile(path, "no triangles with a non-zero area");

  // Normals: the file's or assimp's smooth ones, normalised, checked against the faces. face_sum
  // is the area-weighted sum of the outward normals of a vertex's triangles (idx3d's vertex
  // normal, sphere.h).
  //   - A missing (NaN), infinite or zero-length normal is replaced by normalize(face_sum); if
  //     face_sum is zero too (the triangles cancel, e.g. a two-sided sheet), the vertex has no
  //     usable normal: error.
  //   - A normal pointing against face_sum is negated. The winding decides the outside (it is
  //     what back-face culling uses); a file normal only refines the direction. Files whose
  //     normals are inverted against a correct winding exist (assimp-testmodels'
  //     STL/Spider_*.stl: every facet normal points inward), and shading them unflipped would
  //     light the back of every visible face.
  //   - A normal perpendicular to face_sum (|cos| <= kPerpendicular: zero but for rounding)
  //     points to neither side, and the sign of its dot product is the rounding's (another
  //     order of the same operations gave the other sign: fuzz_mesh, corpus file
  //     finding-normal-perpendicular-to-faces): replaced as a missing one. Where face_sum is
  //     zero (faces that cancel) or not finite there is no side to tell, and the normal stays.
  constexpr double kPerpendicular = 1e-9;  // some 10^6 times the dot product's rounding error
  std::vector<Vec3> face_sum(m.positions.size(), Vec3{0, 0, 0});
  for (const auto& t : m.triangles) {
    const Vec3 w = outwardAreaNormal(m, t);
    for (uint32_t i : t) face_sum[i] += w;
  }
  for (size_t v = 0; v < m.normals.size(); ++v) {
    const Vec3 n = m.normals[v], f = face_sum[v];
    const double len = length(n), flen = length(f), d = dot(n, f);
    const bool faces_tell = flen > 0.0 && std::isfinite(flen);  // face_sum gives a side
    if (std::isfinite(len) && len > 1e-12 && (!faces_tell || std::fabs(d) > kPerpendicular * len * flen)) {
      m.normals[v] = (d < 0 ? -1.0 / len : 1.0 / len) * n;
      continue;
    }
    if (!faces_tell)
      failMeshFile(path, fmt::format("vertex at ({}, {}, {}) has a zero-length normal and its faces' "
                             "normals cancel",
                             m.positions[v].x, m.positions[v].y, -m.positions[v].z));
    m.normals[v] = (1.0 / flen) * f;
  }
  return m;
}

}  // namespace shd
