// render(): the frame, object by object and triangle by triangle. The geometry is
// render/pipeline.h's, the drawing of each screen triangle the method's unit's
// (render/methods.h, render/methods/*.cpp); what is left here is the order: per object its
// lighting and vertices, per mesh triangle culling, the vertex colours, clipping, the method's
// parts of the polygon, and per part the span unit's setup. On two threads the frame is split
// by rows (SplitSide) or into a front and a back end (DrawQueue, BackEnd).
#include "render/render.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <tuple>

#include <immintrin.h>

#include <fmt/format.h>

#include "io/spsc_ring.h"
#include "render/draw.h"
#include "render/methods.h"
#include "render/pipeline.h"
#include "render/split_choice.h"

namespace shd {

// A drawer's buffers kept in a frame's result: the current object's vertices, which of them
// have their colour, the triangles culledEarly keeps (keptTriangles) and their face colours
// (lightFaces).
struct alignas(64) DrawScratch {  // in lines of its own: each side of a split frame writes its own
  std::vector<PVertex> verts;
  std::vector<uint8_t> lit;
  std::vector<uint32_t> kept;
  std::vector<uint8_t> owner;  // on a side of a frame split by rows: whether it owns kept[i]
  std::vector<std::array<double, 3>> faces;
  std::vector<uint8_t> mark;   // triangleNormals's scratch
  std::vector<uint32_t> normal_idx;
};

// The frame's key of a screen triangle: its object, its mesh triangle and which part of it.
struct PartKey {
  uint32_t object, mesh, part;
  bool operator<(const PartKey& o) const { return std::tie(object, mesh, part) < std::tie(o.object, o.mesh, o.part); }
};

// Items 0 .. n - 1 worked on in chunks by both threads of a two-thread frame, one claiming
// chunks from the front and the other from the back, each chunk once, and counted once worked
// (done): whichever thread comes first does what the other has not claimed, so neither waits
// for the other to start. On a frame split by rows the top side works from the front and the
// bottom from the back, so where the mesh's order follows its rows (a sphere's does) each side
// mostly works on the items it reads next, in its own core's cache. Reset by one thread before
// the other can see it.
class SharedChunks {
 public:
  void reset(size_t n) {
    if (n > UINT32_MAX) throw std::length_error("render: an object of more than 2^32 - 1 vertices or triangles");
    n_ = n;
    ends_.store(uint64_t{n} << 32, std::memory_order_relaxed);
    done_.store(0, std::memory_order_relaxed);
  }
  // f(b, e) for each chunk [b, e) of up to `chunk` items it claims, from the front or the back.
  // A chunk f throws in is counted worked all the same (the other thread does not wait forever;
  // the frame is drawn again on one thread, renderSplit).
  template <class F>
  void work(size_t chunk, bool from_back, F&& f) {
    for (uint64_t ends = ends_.load(std::memory_order_relaxed);;) {
      const size_t lo = ends & UINT32_MAX, hi = ends >> 32;
      if (lo >= hi) return;
      const size_t b = from_back ? hi - std::min(chunk, hi - lo) : lo, e = from_back ? hi : std::min(lo + chunk, hi);
      const uint64_t rest = from_back ? uint64_t{b} << 32 | lo : uint64_t{hi} << 32 | e;
      if (!ends_.compare_exchange_weak(ends, rest, std::memory_order_relaxed)) continue;  // ends reloaded
      struct Count {
        std::atomic<size_t>& done;
        size_t n;
        ~Count() { done.fetch_add(n, std::memory_order_release); }
      } count{done_, e - b};
      f(b, e);
      ends = rest;
    }
  }
  // Returns once every item is worked (what the threads wrote then visible here).
  void waitAll() const {
    for (unsigned spin = 0; done_.load(std::memory_order_acquire) < n_; ++spin) spinPause(spin);
  }

 private:
  size_t n_ = 0;
  alignas(64) std::atomic<uint64_t> ends_{0};  // the items not claimed: [low half, high half)
  alignas(64) std::atomic<size_t> done_{0};
};

// An object of a frame split by rows, prepared by both sides together, each pass in
// SharedChunks that both work on and wait for (SceneDrawer::prepareSplitObject): its vertices
// transformed; per mesh triangle its place (0: culled early, else which sides take it and
// whether the top side owns it, SplitSide::place) and, where the method is flat, its face
// colour; then the normals of the vertices of the triangles kept, and where the method reads
// them their colours. After that both sides only read it.
struct SplitObject {
  static constexpr uint8_t kTopTakes = 1, kTopOwns = 2, kBottomTakes = 4;
  std::vector<PVertex> verts;
  std::vector<uint8_t> place;
  std::vector<std::array<double, 3>> faces;
  std::unique_ptr<std::atomic<uint8_t>[]> used;  // per vertex: in a triangle kept (either side sets it)
  size_t used_size = 0;
  SharedChunks transform, cull, light;
  // Sized for an object of nv vertices and nt triangles, its passes not begun.
  void reset(size_t nv, size_t nt) {
    verts.resize(nv);
    place.resize(nt);
    faces.resize(nt);
    if (used_size < nv) {
      used.reset(new std::atomic<uint8_t>[nv]);
      used_size = nv;
    }
    transform.reset(nv);
    cull.reset(nt);
    light.reset(nv);
  }
};

// A side of a two-thread frame split by rows (renderSplit): the rows it draws, and the screen
// triangles it owns. A mesh triangle's owner is the side of its first row that may hold a pixel
// (the top side for a triangle not wholly in front of the near plane, whose rows are known only
// once it is clipped). The owner counts the triangle, sets up each of its parts and records
// those setup keeps (PartKey order: the order of one thread); the other side sets up only the
// parts that may reach its rows. Each side draws its rows of every part it set up, objects
// and triangles in the order of one thread, so each pixel sees the triangles in that order.
// A pixel's tag (Framebuffer::tri) is written as the side's own index of the triangle, or
// kForeignTag plus its index in `foreign`, and made the frame's after both sides end.
struct alignas(64) SplitSide {  // in lines of its own, as DrawScratch
  static constexpr uint32_t kForeignTag = uint32_t{1} << 30;
  RowShare rows{RowShare::Side::Rows};  // its rows, y0 .. y1 - 1
  int32_t H = 0;                        // the frame's rows
  bool top = true;
  // The triangles it owns, in key order: their keys, apart from the rest (the other side reads
  // them to rank both sides' triangles, rankSides), and their descriptions. Only where the
  // frame's order is read (needsOrder), and the descriptions only for the list.
  std::vector<PartKey> keys;
  std::vector<ScreenTriangleInfo> owned;
  Framebuffer drawn;                // no buffers: the rectangle its owned triangles may draw
  std::vector<PartKey> foreign;     // drawn here, owned by the other side, in key order
  std::vector<uint32_t> global;     // the frame's index of owned[i], then of foreign[i]
  RenderStats stats;                // the bottom side's counts (the top counts into the frame's)
  RenderStats others;               // the counts of the other side's triangles (not kept)
  RecordedWalk walk;                // a part set up without rows' spans, walked for its rows
  double seconds = 0;               // the side's time (drawSide)
  std::exception_ptr error;
  std::vector<std::unique_ptr<SplitObject>>* objects = nullptr;  // the frame's, shared by both sides
  // The bottom side's first row.
  int32_t split() const { return top ? rows.y1 : rows.y0; }
  // The rows lo .. hi a triangle whose vertices lie at a, b, c may reach: those of the pixel
  // centres within them, within [floor(ymin), ceil(ymax)], and one more each way (setup's
  // snapping moves a vertex by less than a subpixel), which [trunc(ymin) - 2, trunc(ymax) + 2]
  // holds; clamped to -1 .. H (NaN: -1, on both sides alike).
  std::pair<int32_t, int32_t> rowsOf(const PVertex& a, const PVertex& b, const PVertex& c) const {
    auto row = [this](double y, int32_t d) {
      if (!(y > -1.0)) return -1;
      return y < H ? std::clamp(static_cast<int32_t>(y) + d, -1, H) : H;
    };
    return {row(std::min({a.y, b.y, c.y}), -2), row(std::max({a.y, b.y, c.y}), 2)};
  }
  // Whether a triangle whose vertices lie at a, b, c may reach this side's rows.
  bool reaches(const PVertex& a, const PVertex& b, const PVertex& c) const {
    const auto [lo, hi] = rowsOf(a, b, c);
    return rows.anyIn(lo, hi);
  }
  // The place (SplitObject) of the mesh triangle tv, not culled early: which sides clip it, and
  // whether the top side owns it.
  uint8_t place(const TriangleView& tv) const {
    using O = SplitObject;
    if (!tv.all_in) return O::kTopTakes | O::kTopOwns | O::kBottomTakes;
    const auto [lo, hi] = rowsOf(*tv.v0, *tv.v1, *tv.v2);
    const int32_t s = split();
    const bool top_owns = std::clamp(lo, 0, H - 1) < s;
    const RowShare top_rows{RowShare::Side::Rows, 0, s}, bottom_rows{RowShare::Side::Rows, s, H};
    const bool top_takes = top_owns || top_rows.anyIn(lo, hi), bottom_takes = !top_owns || bottom_rows.anyIn(lo, hi);
    return (top_takes ? O::kTopTakes : 0) | (top_owns ? O::kTopOwns : 0) | (bottom_takes ? O::kBottomTakes : 0);
  }
};

// Whether anything reads the order of a frame's triangles: the tags or the triangle list. A
// frame split by rows ranks its sides' triangles (rankSides) only then.
namespace {
bool needsOrder(const RenderOptions& opt) { return opt.tags || opt.triangles; }
}  // namespace

// A frame's buffers kept in its result (ScratchBuffers): the drawers' buffers (second: the
// second side's of a frame split by rows), the split's sides, and the row it split at last.
struct RenderScratch {
  DrawScratch main, second;
  std::array<SplitSide, 2> sides;
  std::vector<std::unique_ptr<SplitObject>> split_objects;  // the sides' objects (SplitSide::objects)
  int32_t split = -1;
  SplitChoice choice;  // Split::Auto's
};
ScratchBuffers::ScratchBuffers() : p_(std::make_unique<RenderScratch>()) {}
ScratchBuffers::~ScratchBuffers() = default;
ScratchBuffers::ScratchBuffers(const ScratchBuffers&) : ScratchBuffers() {}
ScratchBuffers& ScratchBuffers::operator=(const ScratchBuffers&) { return *this; }

namespace {

// The coding of a device lobe's requests for the specular unit of a material.
DeviceCoding codingFor(SpecEngine* e, const Material& m) {
  DeviceCoding c;
  if (e == nullptr) return c;
  const PromTable& t = e->table();
  c.cos_frac_bits = t.unit.CosFracBits;
  const int a = t.addressOf(std::round(m.shininess));
  if (a < 0)
    throw std::invalid_argument(
        fmt::format("shininess {} is not in the specular unit's PROM (n = {})", m.shininess, t.request.n.text));
  c.shin = static_cast<uint32_t>(a);
  c.zero = e->zeroCode(c.shin);
  return c;
}

// The object's material, lobe and specular unit (Frame::obj).
void lightObject(Frame& f, const Scene& scene, const SpecEngines& engines, size_t oi) {
  const SceneObject& obj = scene.objects[oi];
  const Material& mat = scene.materials.at(static_cast<size_t>(obj.material));
  ObjectShading& o = f.obj;
  o.index = static_cast<int>(oi);
  o.material = &mat;
  o.lobe = parseLobe(f.opt.brdf.empty() ? mat.brdf : f.opt.brdf);
  o.spec = engines.forLobe(o.lobe);
  if (isDeviceLobe(o.lobe) && o.spec == nullptr && !traits(f.opt.method).exact)
    throw std::invalid_argument(fmt::format("object '{}': brdf {} needs the specular unit", obj.name, toString(o.lobe)));
  o.coding = codingFor(o.spec, mat);
  o.shader.emplace(f.ctx, mat, o.lobe, &o.coding);
  o.direct = o.spec != nullptr ? o.spec->model() : nullptr;
}

// The face colours (Frame::faceColour) of an object's triangles, its vertices transformed: of
// those the drawer will draw (kept: keptTriangles's) wholly in front of the near plane, the
// polygons it will draw as the triangles themselves unless the guard band clips them (the
// others' are not set).
void lightFaces(Frame& f, const std::vector<PVertex>& verts, const std::vector<std::array<uint32_t, 3>>& tris,
                const std::vector<uint32_t>& kept, std::vector<std::array<double, 3>>& faces) {
  faces.resize(tris.size());
  for (const uint32_t i : kept) {
    const TriangleView tv = viewTriangle(verts, tris[i], f.proj.z_near);
    if (tv.all_in) faces[i] = f.faceColour(*tv.v0, *tv.v1, *tv.v2);
  }
}

// An object's vertices transformed by both threads of a two-thread frame (SharedChunks); the
// front end waits until all are done before its first triangle. The back end helps when it
// reaches the object's mark: at once at the frame's start, where it has nothing else to do;
// later objects the front end mostly transforms alone, the back end still busy with the object
// before.
struct SharedTransform {
  const SceneObject* obj = nullptr;
  const CameraBasis* basis = nullptr;
  const Camera* cam = nullptr;
  const Projection* proj = nullptr;
  PVertex* verts = nullptr;
  bool vector = true;  // Frame::avx2
  bool normals = true;  // not MethodTraits::face_colours
  SharedChunks chunks;

  static constexpr size_t kChunk = 64;
  void work(bool back_end) {
    chunks.work(kChunk, back_end, [this](size_t b, size_t e) {
      transformVertexRange(*obj, *basis, *cam, *proj, verts, b, e, vector, normals);
    });
  }
};

// A screen triangle's vertices as set up: position and the renderer's 4 attributes (colour or
// normal, and depth), in the attributes' units.
using SetupInput = std::array<RowSpans::Vertex, 3>;

// A screen triangle's setup: as its rows' spans where its method and the triangle allow
// (raster/row_spans.h), else by the span unit's setup. The frame's configurations, of colour or
// normal attributes; a two-thread frame's back end has a copy of the front end's.
struct TriangleSetup {
  RasterConfig rc_colour, rc_unit;                   // colour or normal attributes (and depth)
  std::optional<RowSpansConfig> rs_colour, rs_unit;  // and as rows' spans (empty: not at all)
  const RasterConfig& raster(bool colour_attrs) const { return colour_attrs ? rc_colour : rc_unit; }
  // v of method m set up into rows (spans = true) or setup: false when dropped (no pixel centre
  // inside). tag: the triangle's id, in setup's descriptor and its errors.
  bool run(const SetupInput& v, Method m, bool colour_attrs, uint32_t tag, RowSpans& rows, SetupResult& setup,
           bool& spans) const {
    const RowSpansConfig* rs = rowSpans(m, colour_attrs);
    spans = false;
    if (rs != nullptr) {
      const RowSpansSetup got = setupRowSpans(v, *rs, rows);
      if (got == RowSpansSetup::Dropped) return false;
      if (got == RowSpansSetup::Drawn) return spans = true;
    }
    return general(v, colour_attrs, tag, setup);
  }
  // The configuration a triangle of method m is set up to its rows' spans with, or null.
  const RowSpansConfig* rowSpans(Method m, bool colour_attrs) const {
    const std::optional<RowSpansConfig>& rs = colour_attrs ? rs_colour : rs_unit;
    return rs && traits(m).row_spans ? &*rs : nullptr;
  }
  // By the span unit's setup (false: dropped).
  bool general(const SetupInput& v, bool colour_attrs, uint32_t tag, SetupResult& setup) const {
    std::array<SetupVertex, 3> sv;
    for (size_t i = 0; i < 3; ++i) {
      sv[i].x = v[i].x;
      sv[i].y = v[i].y;
      sv[i].attr.resizeForOverwrite(4);
      for (size_t k = 0; k < 4; ++k) sv[i].attr[k] = v[i].attr[k];
    }
    setupTriangle(sv, tag, raster(colour_attrs), setup);
    return setup.desc.has_value();
  }
};

// Whether both sides of a two-thread frame draw a triangle of method m of the object o, each
// the rows of its RowShare: a method walked ahead, and no specular-unit requests (the unit's
// batch cycles are counted per triangle, so a device lobe's triangle is the back end's alone).
bool rowsShared(Method m, const ObjectShading& o) {
  return traits(m).two_threads == TwoThreads::AfterWalk && o.spec == nullptr;
}

// A screen triangle of a two-thread frame, or a mark between objects, on its way from the
// front end (SceneDrawer on the calling thread: culling, vertex colours, clipping, setup) to the
// back end (drawBackEnd: the method's unit walks, z-tests, shades and writes it). A triangle of
// a TwoThreads::AfterSetup method is recorded (its tag, RenderResult::triangles, the drawn
// rectangle) by the back end, and may be handed to it before setup (set_up false: it sets it up
// from `in`) while the back end is short of work (RenderOptions::hand_off_below). Which side
// sets a triangle up changes no byte of the frame and no count: the back end counts the
// triangles drawn, the side that set a mesh triangle up counts it if setup drops it whole.
struct DrawJob {
  enum class Kind : uint8_t { Triangle, BeginObject, EndObject, End };
  static constexpr uint8_t kFirstPart = 1, kLastPart = 2;
  Kind kind = Kind::End;
  Method method = Method::Gouraud;  // Triangle: of the unit that draws it
  bool colour_attrs = true;         // Triangle: set up with colour attributes (else normals)
  bool set_up = true;               // Triangle: set up by the front end, else handed off
  uint8_t mesh_parts = 0;           // handed off: kFirstPart, kLastPart of its mesh triangle's parts
  uint32_t tag = 0;                 // Triangle, AfterWalk (AfterSetup: the back end gives it)
  size_t object = 0;                // BeginObject
  ScreenTriangleInfo info;          // Triangle, AfterSetup: for the back end to record
  SetupInput in;                    // Triangle, handed off: what the back end sets up
  mutable SharedTransform transform;  // BeginObject: its vertices, which the back end helps with
  bool spans = false;               // Triangle: set up as rows' spans (else by setup)
  SetupResult setup;                // Triangle, unless spans
  RowSpans rows;                    // Triangle, if spans
  RecordedWalk walk;                // Triangle: the front end's walk, for a TwoThreads::AfterWalk method
};

// Thrown by a two-thread frame's front end after it has handed the back end a triangle whose
// setup failed (SceneDrawer::queueSetUp).
struct SetupHandedOff {};

// The lines of a job's slot that setting a triangle up writes (its rows' spans where the slot's
// last triangle had them, else the descriptor's head, planes and first lane-triangle, the
// snapped triangle, the edge functions, the plane) and, for a walk recorded ahead, as many
// events as the slot's last walk had, fetched for writing
// (PREFETCHW) two jobs before the front end reaches the slot, which the back end's core read
// last. Without it a store waits for its line: when this VM's two cores are far apart (a
// core-to-core round trip of 550 ns instead of 120) gouraud's two-thread frame on
// builtin:sphere took 1.11 ms, more than one thread's, and 0.585 with it (docs/performance.md;
// the whole slot fetched: 0.85-0.91, and 3 % slower when the cores are near).
void prefetchJobForWrite(const DrawJob& j) {
  auto object = [](const auto& o) { prefetchForWrite(&o, &o + 1); };
  const SetupResult& s = j.setup;
  prefetchForWrite(&j, &j.transform);
  if (j.spans) {
    object(j.rows);
    return;
  }
  if (s.desc) {
    prefetchForWrite(&*s.desc, &s.desc->tri[0] + 1);
    prefetchForWrite(reinterpret_cast<const char*>(&s.desc + 1) - 1, &s.desc + 1);  // the lane-triangles' count, engaged
  }
  object(s.dropped);
  object(s.tri);
  object(s.edges);
  object(s.plane);
  prefetchForWrite(j.walk.events.data(), j.walk.events.data() + j.walk.events.size());  // as many as the slot's last walk
}

// The jobs in order, from the front end to the back end: 256 slots, shown 16 at a time and at
// each object's start (its vertices, which the back end helps with) and the frame's end.
using DrawQueue = SpscRing<DrawJob, 256, 16>;

// The thread that draws the back ends of two-thread frames: made with the first and kept for
// the next, one frame at a time (`frame`). Between frames it spins for up to 2 ms before it
// sleeps, so that frame after frame it stays on its own core: a thread made per frame, or one
// woken from sleep, is put on the core of the thread that makes or wakes it, and there it ran
// the whole of builtin:sphere's frame (about a millisecond) before the scheduler moved it: 1.4
// to 2.5 ms a frame instead of 0.7.
class BackThread {
 public:
  static BackThread& instance() {
    static BackThread t;
    return t;
  }
  std::mutex frame;  // held by a two-thread frame from start() to wait()
  DrawQueue queue;   // the frame's (under `frame`): its slots' memory kept from frame to frame
  // Runs job (which must not throw) on the back thread; wait() returns once it has.
  void start(const std::function<void()>& job) {
    job_ = &job;
    {
      std::lock_guard<std::mutex> l(m_);
      posted_.fetch_add(1, std::memory_order_release);
    }
    wake_.notify_one();
  }
  // Spins before it sleeps (spinFor), as the back thread does between frames: woken from
  // sleep, this thread was put on the back thread's core, and both sides of the next frame split
  // by rows ran on one core (its frames took 0.95 of one thread's time).
  void wait() {
    const uint64_t posted = posted_.load(std::memory_order_relaxed);
    const auto done = [&] { return done_.load(std::memory_order_acquire) == posted; };
    if (spinFor(done)) return;
    std::unique_lock<std::mutex> l(m_);
    finished_.wait(l, done);
  }
  ~BackThread() {
    {
      std::lock_guard<std::mutex> l(m_);
      stop_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
  BackThread(const BackThread&) = delete;
  BackThread& operator=(const BackThread&) = delete;

 private:
  BackThread() : thread_([this] { loop(); }) {}
  // Whether ready() holds within 2 ms of spinning (the clock read every 256 pauses).
  template <class Ready>
  static bool spinFor(Ready ready) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(2);
    for (unsigned spin = 1; !ready(); ++spin) {
      if (spin % 256 == 0 && std::chrono::steady_clock::now() > until) return ready();
      _mm_pause();
    }
    return true;
  }
  void loop() {
    for (uint64_t taken = 0;;) {
      const auto posted = [&] { return posted_.load(std::memory_order_acquire) != taken; };
      if (!spinFor(posted)) {
        std::unique_lock<std::mutex> l(m_);
        wake_.wait(l, [&] { return stop_ || posted(); });
        if (stop_) return;
      }
      taken = posted_.load(std::memory_order_acquire);
      (*job_)();
      {
        std::lock_guard<std::mutex> l(m_);
        done_.store(taken, std::memory_order_release);
      }
      finished_.notify_one();
    }
  }
  std::mutex m_;
  std::condition_variable wake_, finished_;
  const std::function<void()>* job_ = nullptr;  // written before posted_ grows
  std::atomic<uint64_t> posted_{0}, done_{0};
  bool stop_ = false;  // under m_
  std::thread thread_;  // last: started once the members above exist
};

// The objects of a frame, drawn by the unit of the frame's method, with the buffers of the
// per-triangle work reused across the frame (no allocation per triangle once they have grown).
class SceneDrawer {
 public:
  // scratch: the drawer's buffers. queue: a two-thread frame's, to which the screen triangles go
  // (else they are drawn here); cleared: its back end has cleared the buffers (the front end
  // draws its share of the triangles walked ahead after that). side: a side of a frame split by
  // rows, which draws its rows and records the triangles it owns there (not in res).
  SceneDrawer(Frame& f, const Scene& scene, const SpecEngines& engines, RenderResult& res, DrawScratch& scratch,
              DrawQueue* queue = nullptr, const std::atomic<bool>* cleared = nullptr, SplitSide* side = nullptr);
  void drawObject(size_t oi);
  const TriangleSetup& triangleSetup() const { return setup_config_; }

 private:
  void lightVertices(const std::array<uint32_t, 3>& tri);
  void walkAhead(const SpanDesc& d, RecordedWalk& w, bool count = true);
  size_t prepareObject(size_t oi);
  size_t prepareSplitObject(size_t oi);
  void drawMeshTriangle(const std::array<uint32_t, 3>& tri, uint32_t ti);
  bool setUpLater(uint32_t ti, bool owner);
  void drawSetUp();
  void drawSplitTriangle(const std::array<uint32_t, 3>& tri, uint32_t ti, bool owner);
  bool drawPart(const Part& part, uint32_t ti, uint8_t hand_off);
  bool drawSplitPart(const Part& part, uint32_t ti, uint32_t k, bool owner);
  uint32_t nextTag(bool owner) const;
  void drawSplitSetUp(const Part& part, uint32_t ti, uint32_t k, bool owner, bool meets, const RowSpans* rows,
                      uint32_t tag);
  bool queueSetUp(const Part& part, uint32_t ti, const SetupInput& in, DrawJob& job, uint8_t hand_off);
  void setupInput(const Part& part, bool colour_attrs, SetupInput& in) const;

  Frame& f_;
  const Scene& scene_;
  const SpecEngines& engines_;
  std::vector<ScreenTriangleInfo>& triangles_;  // the result's: where each screen triangle came from
  const CameraBasis basis_;
  MethodUnit& unit_;                  // the frame's method's
  const bool vertex_colours_;         // the method's
  const bool face_colours_;           // the method's (and so no vertex normals)
  // A two-thread frame of a TwoThreads::AfterSetup method: the back end records the triangles.
  const bool back_records_;
  TriangleSetup setup_config_;
  // The result's buffers (DrawScratch): the object's vertices, which of their colours are
  // computed (lit), its triangles not culled early (kept, and a side's owner flags), its face
  // colours lit ahead (faces), the normals' scratch.
  DrawScratch& scratch_;
  // The object's vertices and face colours: scratch_'s, or on a side of a frame split by rows
  // the SplitObject's.
  std::vector<PVertex>* verts_ = nullptr;
  std::vector<std::array<double, 3>>* faces_ = nullptr;
  bool faces_lit_ = false;            // this object's faces_ (MethodTraits::face_colours)
  Poly poly_;                         // a clipped triangle
  Fan fan_;                           // the polygon to draw
  Parts parts_;                       // its screen triangles
  DrawQueue* const queue_;
  const std::atomic<bool>* const cleared_;
  SplitSide* const side_;
  SetupResult setup_;                 // of the triangle being drawn here (no queue)
  RowSpans rows_;                     // the same as rows' spans
  // One thread or a side of a frame split by rows, where the rows' spans' vector kernels run
  // (AVX-512 or AVX2): mesh triangles drawn as themselves (one part, the mesh's own vertices), set up to
  // their rows' spans 8 at a time (setupRowSpansBlock) and then drawn in order, before anything
  // else is drawn (drawSetUp). On a side: whether it owns each and whether it may reach its rows.
  struct Waiting {
    Part part;
    uint32_t ti;
    bool owner, meets;
  };
  bool blocks_ = false;
  size_t waiting_ = 0;
  bool waiting_colour_ = false;  // their attributes (TriangleSetup::rowSpans's configuration)
  std::array<Waiting, 8> wait_;
  std::array<SetupInput, 8> wait_in_;
  std::array<RowSpans, 8> wait_rows_;
  std::array<RowSpansSetup, 8> wait_got_;
};

// The pixels a recorded screen triangle may draw, in the framebuffer's drawn rectangle.
void markDrawn(Framebuffer& fb, const ScreenTriangleInfo& info) {
  const auto& p = info.xy;
  fb.markDrawn(std::min({p[0][0], p[1][0], p[2][0]}), std::min({p[0][1], p[1][1], p[2][1]}),
               std::max({p[0][0], p[1][0], p[2][0]}), std::max({p[0][1], p[1][1], p[2][1]}));
}

// A screen triangle that setup kept, described in info (where it came from: object, mesh
// triangle ti, xy(i) its vertex i's screen position) and counted (drawn, row_spans).
template <class XY>
void describeTriangle(int object, uint32_t ti, XY xy, bool spans, ScreenTriangleInfo& info, RenderStats& st) {
  info.object = object;
  info.mesh_triangle = ti;
  for (size_t i = 0; i < 3; ++i) info.xy[i] = xy(i);
  ++st.drawn;
  st.row_spans += spans;
}
// ... and recorded: its tag (the next index of `triangles`), and the pixels it may draw in the
// framebuffer's drawn rectangle.
template <class XY>
uint32_t recordTriangle(int object, uint32_t ti, XY xy, bool spans, std::vector<ScreenTriangleInfo>& triangles,
                        RenderStats& st, Framebuffer& fb) {
  const uint32_t tag = static_cast<uint32_t>(triangles.size());
  // Filled in place: a local copied in stalled on its own partial stores.
  ScreenTriangleInfo& info = triangles.emplace_back();
  describeTriangle(object, ti, xy, spans, info, st);
  markDrawn(fb, info);
  return tag;
}

// Vertex i's screen position of a part (recordTriangle).
auto partXY(const Part& part) {
  return [&part](size_t i) { return std::array<double, 2>{part.v[i]->x, part.v[i]->y}; };
}

SceneDrawer::SceneDrawer(Frame& f, const Scene& scene, const SpecEngines& engines, RenderResult& res,
                         DrawScratch& scratch, DrawQueue* queue, const std::atomic<bool>* cleared, SplitSide* side)
    : f_(f),
      scene_(scene),
      engines_(engines),
      triangles_(res.triangles),
      basis_(cameraBasis(scene.camera)),
      unit_(f.unit(f.opt.method)),
      vertex_colours_(traits(f.opt.method).vertex_colours),
      face_colours_(traits(f.opt.method).face_colours),
      back_records_(queue != nullptr && traits(f.opt.method).two_threads == TwoThreads::AfterSetup),
      scratch_(scratch),
      queue_(queue),
      cleared_(cleared),
      side_(side) {
  RasterConfig rc;
  rc.width = f.W;
  rc.height = f.H;
  rc.subpixel_bits = f.opt.subpixel_bits;
  rc.unit = f.span.params();
  if (rc.unit.NumAttr != 4) throw std::invalid_argument("render: the span unit must carry 4 attributes");
  rc.attr_frac_bits = {kColourFrac, kColourFrac, kColourFrac, kUnitFrac};
  rc.validate();
  TriangleSetup& c = setup_config_;
  c.rc_colour = c.rc_unit = rc;
  // The normal at phong-fixed's NormalFracBits when it runs at runtime widths; the depth as ever.
  const int normal_frac = f.opt.phong_widths ? f.opt.phong_widths->NormalFracBits : kUnitFrac;
  c.rc_unit.attr_frac_bits = {normal_frac, normal_frac, normal_frac, kUnitFrac};
  // Rows' spans need the model's walk (the RTL takes descriptors).
  if (f.opt.row_spans && f.walker != nullptr) {
    c.rs_colour.emplace(c.rc_colour);
    c.rs_unit.emplace(c.rc_unit);
    if (!c.rs_colour->applies) c.rs_colour.reset();
    if (!c.rs_unit->applies) c.rs_unit.reset();
    for (std::optional<RowSpansConfig>* rs : {&c.rs_colour, &c.rs_unit})
      if (*rs) {
        (*rs)->vector = f.avx2;
        (*rs)->avx512 = f.avx2 && fixed_simd::available();
      }
  }
}

void SceneDrawer::drawObject(size_t oi) {
  const SceneObject& obj = scene_.objects[oi];
  lightObject(f_, scene_, engines_, oi);
  for (const auto& u : f_.units()) u.second->beginObject();
  // On one thread, where no specular unit counts the lighting (Frame::shadeNow). (On two, the
  // pass delays the back end's first triangles: flat's frame took 1.03-1.06 times as long with
  // it, the pass shared between both threads, docs/performance.md.)
  faces_lit_ = face_colours_ && queue_ == nullptr && f_.obj.spec == nullptr;
  // The back faces culled early, counted at once (on a side of a frame split by rows, those it
  // culled).
  const size_t culled = side_ != nullptr ? prepareSplitObject(oi) : prepareObject(oi);
  f_.st.triangles += culled;
  f_.st.culled_back += culled;
  // (Not where a specular unit counts the requests: a waiting triangle's vertices are lit
  // before the triangles ahead of it are drawn.)
  blocks_ = queue_ == nullptr && f_.obj.spec == nullptr;
  const std::vector<uint32_t>& kept = scratch_.kept;
  uint32_t ti = 0;
  try {
    for (size_t j = 0; j < kept.size(); ++j) {
      ti = kept[j];
      if (side_ != nullptr) drawSplitTriangle(obj.mesh.triangles[ti], ti, scratch_.owner[j] != 0);
      else drawMeshTriangle(obj.mesh.triangles[ti], ti);
      if (waiting_ == wait_.size()) drawSetUp();
    }
    drawSetUp();
  } catch (const std::range_error& e) {
    throw std::range_error(fmt::format("{}: object '{}' triangle {}: {}", scene_.name, obj.name, ti, e.what()));
  }
  for (const auto& u : f_.units()) u.second->endObject();
  if (queue_ != nullptr) {
    DrawJob& j = queue_->slot();
    j.kind = DrawJob::Kind::EndObject;
    j.object = oi;
    queue_->push();
  }
}

// One thread, or the front end of a two-thread frame: the object's vertices transformed (by
// both threads on two), its back faces culled early (returns how many), the normals of the
// vertices drawn, the face colours lit ahead.
size_t SceneDrawer::prepareObject(size_t oi) {
  const SceneObject& obj = scene_.objects[oi];
  verts_ = &scratch_.verts;
  faces_ = &scratch_.faces;
  scratch_.verts.resize(obj.mesh.positions.size());  // kept from the frame before: nothing to clear
  if (queue_ == nullptr) {
    transformVertexRange(obj, basis_, scene_.camera, f_.proj, scratch_.verts.data(), 0, scratch_.verts.size(), f_.avx2,
                         false);
  } else {
    DrawJob& j = queue_->slot();
    j.kind = DrawJob::Kind::BeginObject;
    j.object = oi;
    SharedTransform& t = j.transform;
    t.obj = &obj;
    t.basis = &basis_;
    t.cam = &scene_.camera;
    t.proj = &f_.proj;
    t.verts = scratch_.verts.data();
    t.vector = f_.avx2;
    t.normals = !face_colours_;
    t.chunks.reset(scratch_.verts.size());
    queue_->push(true);  // shown to the back end at once (release)
    t.work(false);
    t.chunks.waitAll();
  }
  std::vector<uint32_t>& kept = scratch_.kept;
  const size_t culled = keptTriangles(scratch_.verts, obj.mesh.triangles, f_.proj.z_near, kept);
  // The normals of the vertices drawn (transformed without them above), where the method reads
  // them; the two-thread frame's shared transform gave every vertex its normal.
  if (queue_ == nullptr && !face_colours_)
    triangleNormals(obj, basis_, kept, scratch_.verts.data(), scratch_.mark, scratch_.normal_idx, f_.avx2);
  if (faces_lit_) lightFaces(f_, scratch_.verts, obj.mesh.triangles, kept, scratch_.faces);
  scratch_.lit.assign(scratch_.verts.size(), 0);
  return culled;
}

// A side of a frame split by rows: the object prepared by both sides (SplitObject; returns how
// many back faces this side culled early), and then this side's triangles: those it takes, in
// order, and whether it owns each (DrawScratch::kept, owner).
size_t SceneDrawer::prepareSplitObject(size_t oi) {
  const SceneObject& obj = scene_.objects[oi];
  const std::vector<std::array<uint32_t, 3>>& tris = obj.mesh.triangles;
  SplitObject& so = *(*side_->objects)[oi];
  verts_ = &so.verts;
  faces_ = &so.faces;
  const bool from_back = !side_->top, normals = !face_colours_;
  constexpr size_t kVertexChunk = 64, kTriangleChunk = 256;
  so.transform.work(kVertexChunk, from_back, [&](size_t b, size_t e) {
    transformVertexRange(obj, basis_, scene_.camera, f_.proj, so.verts.data(), b, e, f_.avx2, false);
    if (normals)
      for (size_t i = b; i < e; ++i) so.used[i].store(0, std::memory_order_relaxed);
  });
  so.transform.waitAll();
  size_t culled = 0;
  so.cull.work(kTriangleChunk, from_back, [&](size_t b, size_t e) {
    for (size_t t = b; t < e; ++t) {
      const TriangleView tv = viewTriangle(so.verts, tris[t], f_.proj.z_near);
      const bool keep = !culledEarly(tv);
      so.place[t] = keep ? side_->place(tv) : 0;
      culled += !keep;
      if (keep && normals)
        for (const uint32_t i : tris[t]) so.used[i].store(1, std::memory_order_relaxed);
      if (keep && faces_lit_ && tv.all_in) so.faces[t] = f_.faceColour(*tv.v0, *tv.v1, *tv.v2);
    }
  });
  so.cull.waitAll();
  if (normals) {
    so.light.work(kVertexChunk, from_back, [&](size_t b, size_t e) {
      std::array<uint32_t, kVertexChunk> idx;
      size_t m = 0;
      for (size_t i = b; i < e; ++i) {
        idx[m] = static_cast<uint32_t>(i);
        m += so.used[i].load(std::memory_order_relaxed);
      }
      vertexNormals(obj, basis_, idx.data(), m, so.verts.data(), f_.avx2);
      if (vertex_colours_)
        for (size_t j = 0; j < m; ++j) {
          PVertex& v = so.verts[idx[j]];
          v.colour = f_.shadeNow(v.n, v.cam);
        }
    });
    so.light.waitAll();
  }
  const uint8_t takes = side_->top ? SplitObject::kTopTakes : SplitObject::kBottomTakes;
  const uint8_t owns = side_->top ? SplitObject::kTopOwns : 0;
  std::vector<uint32_t>& kept = scratch_.kept;
  std::vector<uint8_t>& owner = scratch_.owner;
  kept.resize(tris.size());
  owner.resize(tris.size());
  size_t n = 0;
  for (size_t t = 0; t < tris.size(); ++t) {
    const uint8_t p = so.place[t];
    kept[n] = static_cast<uint32_t>(t);
    owner[n] = (p & SplitObject::kTopOwns) == owns;
    n += (p & takes) != 0;  // without a branch
  }
  kept.resize(n);
  owner.resize(n);
  return culled;
}

// Gouraud vertex colours: computed when a triangle that is not culled first needs them.
void SceneDrawer::lightVertices(const std::array<uint32_t, 3>& tri) {
  for (const uint32_t i : tri)
    if (!scratch_.lit[i]) {
      scratch_.verts[i].colour = f_.shadeNow(scratch_.verts[i].n, scratch_.verts[i].cam);
      scratch_.lit[i] = 1;
    }
}

// A mesh triangle not culled early that a side of a frame split by rows takes
// (prepareSplitObject): its owner's to count. Its vertices' colours are lit already.
void SceneDrawer::drawSplitTriangle(const std::array<uint32_t, 3>& tri, uint32_t ti, bool owner) {
  const TriangleView tv = viewTriangle(*verts_, tri, f_.proj.z_near);
  RenderStats& st = owner ? f_.st : side_->others;
  ++st.triangles;
  if (!clipToFan(tv, f_.proj, f_.W, f_.H, poly_, fan_, st)) return;
  parts_.clear();
  f_.face_colour = faces_lit_ && fan_[0] == tv.v0 ? &(*faces_)[ti] : nullptr;
  unit_.parts(fan_, parts_);
  if (blocks_ && fan_[0] == tv.v0 && setUpLater(ti, owner)) return;
  drawSetUp();  // the triangles waiting first
  bool drawn = false;
  for (size_t k = 0; k < parts_.size(); ++k) drawn |= drawSplitPart(parts_[k], ti, static_cast<uint32_t>(k), owner);
  if (!drawn) ++st.culled_no_pixel;
}

void SceneDrawer::drawMeshTriangle(const std::array<uint32_t, 3>& tri, uint32_t ti) {
  RenderStats& st = f_.st;
  ++st.triangles;
  const TriangleView tv = viewTriangle(*verts_, tri, f_.proj.z_near);
  if (vertex_colours_) lightVertices(tri);
  if (!clipToFan(tv, f_.proj, f_.W, f_.H, poly_, fan_, st)) return;
  // Lit ahead: a triangle drawn as itself (a clipped one's fan points into poly_).
  f_.face_colour = faces_lit_ && fan_[0] == tv.v0 ? &(*faces_)[ti] : nullptr;
  // The screen triangles to draw (a fan of the polygon), each with the unit that draws it:
  // modified Gouraud may split one into parts, adaptive picks per triangle.
  parts_.clear();
  unit_.parts(fan_, parts_);
  if (blocks_ && fan_[0] == tv.v0 && setUpLater(ti, true)) return;
  drawSetUp();  // the triangles waiting first
  // Every part handed to the back end before setup (it then counts the mesh triangle if setup
  // drops them all), while fewer than hand_off_below jobs wait for it.
  const bool hand_off = back_records_ && !parts_.empty() && queue_->backlog() < f_.opt.hand_off_below;
  bool drawn = false;
  for (size_t k = 0; k < parts_.size(); ++k) {
    const uint8_t first = k == 0 ? DrawJob::kFirstPart : 0, last = k + 1 == parts_.size() ? DrawJob::kLastPart : 0;
    drawn |= drawPart(parts_[k], ti, hand_off ? first | last : 0);
  }
  if (!drawn && !hand_off) ++st.culled_no_pixel;  // every part dropped by setup: nothing on screen
}

// The triangle drawn as itself (parts_) into the triangles waiting for setupRowSpansBlock, where
// its one part has the mesh's vertices and is set up to its rows' spans in vector lanes with the
// configuration of those waiting (else they are drawn first), and on a side of a frame split by
// rows, where the side sets it up (drawSplitPart): false where it is not. owner: the side's.
bool SceneDrawer::setUpLater(uint32_t ti, bool owner) {
  if (parts_.size() != 1) return false;
  const Part& part = parts_[0];
  const bool colour_attrs = traits(part.method).attributes == Attributes::Colour;
  const RowSpansConfig* rs = setup_config_.rowSpans(part.method, colour_attrs);
  if (rs == nullptr || !rs->vector) return false;
  const PVertex* const verts = verts_->data();
  for (const PVertex* v : part.v)
    if (v < verts || v >= verts + verts_->size()) return false;
  bool meets = true;
  if (side_ != nullptr) {
    meets = side_->reaches(*part.v[0], *part.v[1], *part.v[2]);
    if (!owner && !meets) return false;
  }
  if (waiting_ > 0 && colour_attrs != waiting_colour_) drawSetUp();
  waiting_colour_ = colour_attrs;
  // Field by field, and the vertices written in place: a braced temporary, or the part or the
  // setup input copied whole, is copied with 16-byte loads of what was just stored 8 bytes at a
  // time, which the processor cannot forward (a store-forwarding stall: most of this function's
  // samples, 4.5 % of a phong-fixed frame at 128 segments).
  Waiting& w = wait_[waiting_];
  for (size_t i = 0; i < 3; ++i) w.part.v[i] = part.v[i];
  w.part.unit = part.unit;
  w.part.method = part.method;
  w.part.colour = part.colour;
  w.ti = ti;
  w.owner = owner;
  w.meets = meets;
  setupInput(part, colour_attrs, wait_in_[waiting_]);
  ++waiting_;
  return true;
}

// The triangles waiting, set up and drawn in order, as drawPart (one thread) or drawSplitPart
// (a side of a frame split by rows) draws each.
void SceneDrawer::drawSetUp() {
  if (waiting_ == 0) return;
  const size_t n = waiting_;
  waiting_ = 0;
  const RowSpansConfig& rs = *(waiting_colour_ ? setup_config_.rs_colour : setup_config_.rs_unit);
  setupRowSpansBlock(wait_in_.data(), n, rs, wait_rows_.data(), wait_got_.data());
  const RasterConfig& rc = setup_config_.raster(waiting_colour_);
  for (size_t t = 0; t < n; ++t) {
    const Waiting& w = wait_[t];
    const Part& part = w.part;
    const uint32_t tag = nextTag(w.owner);
    const bool spans = wait_got_[t] == RowSpansSetup::Drawn;
    const bool set_up = spans || (wait_got_[t] == RowSpansSetup::General &&
                                  setup_config_.general(wait_in_[t], waiting_colour_, tag, setup_));
    if (!set_up) {
      ++(w.owner ? f_.st : side_->others).culled_no_pixel;  // no pixel centre inside
      continue;
    }
    if (side_ != nullptr) {
      drawSplitSetUp(part, w.ti, 0, w.owner, w.meets, spans ? &wait_rows_[t] : nullptr, tag);
      continue;
    }
    recordTriangle(f_.obj.index, w.ti, partXY(part), spans, triangles_, f_.st, f_.fb);
    part.unit->draw(
        SpanTriangle{part.v, part.method, spans ? nullptr : &setup_, spans ? &wait_rows_[t] : nullptr, rc, tag});
  }
}

// A part's vertices as its unit sets them up (into in): colour (the part's own, flat's, or the
// vertex's, clamped to 0..255) or normal, and depth.
void SceneDrawer::setupInput(const Part& part, bool colour_attrs, SetupInput& in) const {
  for (size_t i = 0; i < 3; ++i) {
    const PVertex& v = *part.v[i];
    in[i].x = v.x;
    in[i].y = v.y;
    if (colour_attrs) {
      const std::array<double, 3>& c = part.colour != nullptr ? *part.colour : v.colour;
      for (size_t k = 0; k < 3; ++k) in[i].attr[k] = std::clamp(c[k], 0.0, 255.0);
    } else {
      in[i].attr = {v.n.x, v.n.y, v.n.z, 0};
    }
    in[i].attr[3] = v.w;
  }
}

// A part set up (dropped: false), recorded, and drawn by its unit, or in a two-thread frame
// queued for the back end (hand_off: DrawJob::mesh_parts, handed to it before setup; returns
// true).
bool SceneDrawer::drawPart(const Part& part, uint32_t ti, uint8_t hand_off) {
  const MethodTraits& tr = traits(part.method);
  const bool colour_attrs = tr.attributes == Attributes::Colour;
  const RasterConfig& rc = setup_config_.raster(colour_attrs);
  SetupInput in;
  setupInput(part, colour_attrs, in);
  DrawJob* job = queue_ != nullptr ? &queue_->slot() : nullptr;
  if (job != nullptr) {
    prefetchJobForWrite(queue_->ahead(2));
    job->kind = DrawJob::Kind::Triangle;  // pushed only if setup keeps it
    job->method = part.method;
    job->colour_attrs = colour_attrs;
  }
  if (back_records_) return queueSetUp(part, ti, in, *job, hand_off);
  const uint32_t tag = nextTag(true);
  SetupResult& s = job != nullptr ? job->setup : setup_;
  RowSpans& r = job != nullptr ? job->rows : rows_;
  bool spans = false;
  if (!setup_config_.run(in, part.method, colour_attrs, tag, r, s, spans)) return false;  // no pixel centre inside
  const SetupResult* setup = spans ? nullptr : &s;
  const RowSpans* rows = spans ? &r : nullptr;
  recordTriangle(f_.obj.index, ti, partXY(part), spans, triangles_, f_.st, f_.fb);
  if (job == nullptr) {
    part.unit->draw(SpanTriangle{part.v, part.method, setup, rows, rc, tag});
    return true;
  }
  job->set_up = true;
  job->tag = tag;
  job->spans = spans;
  // A method walked ahead: its rows counted here, on this side, with the span engine's stream
  // (as walkAhead counts), and drawn by the back end from the rows, or where rowsShared, by
  // both sides, each its RowShare of them.
  if (tr.two_threads == TwoThreads::AfterWalk) {
    if (rows != nullptr) f_.countRows(*rows);
    else walkAhead(*setup->desc, job->walk);
  }
  queue_->push();
  // The slot stays as written until this side takes it again. Rows' spans without a row of
  // this side's are not drawn here.
  const RowShare front{RowShare::Side::Front};
  if (!rowsShared(part.method, f_.obj) || (rows != nullptr && !front.anyRow(*rows))) return true;
  for (unsigned spin = 0; !cleared_->load(std::memory_order_acquire); ++spin) spinPause(spin);
  part.unit->draw(SpanTriangle{part.v, part.method, setup, rows, rc, tag, rows != nullptr ? nullptr : &job->walk,
                               rows != nullptr, front});
  return true;
}

// A part on a side of a frame split by rows (SplitSide): set up (false: dropped, or not this
// side's), recorded and counted by its owner, its rows of this side drawn (drawSplitSetUp).
bool SceneDrawer::drawSplitPart(const Part& part, uint32_t ti, uint32_t k, bool owner) {
  const bool meets = side_->reaches(*part.v[0], *part.v[1], *part.v[2]);
  if (!owner && !meets) return false;
  const bool colour_attrs = traits(part.method).attributes == Attributes::Colour;
  const uint32_t tag = nextTag(owner);
  bool spans = false;
  SetupInput in;
  setupInput(part, colour_attrs, in);
  if (!setup_config_.run(in, part.method, colour_attrs, tag, rows_, setup_, spans))
    return false;  // no pixel centre inside
  drawSplitSetUp(part, ti, k, owner, meets, spans ? &rows_ : nullptr, tag);
  return true;
}

// The tag of the next screen triangle set up here: the frame's next index; on a side of a frame
// split by rows, its own index of those it owns (owner), or kForeignTag plus the index of those
// it draws for the other side.
uint32_t SceneDrawer::nextTag(bool owner) const {
  if (side_ == nullptr) return static_cast<uint32_t>(triangles_.size());
  return owner ? static_cast<uint32_t>(side_->keys.size())
               : SplitSide::kForeignTag + static_cast<uint32_t>(side_->foreign.size());
}

// Part k of mesh triangle ti, set up on a side of a frame split by rows (as rows, else setup_)
// with its tag (nextTag): recorded and counted if the side owns it, its rows of the side drawn
// if it meets them.
void SceneDrawer::drawSplitSetUp(const Part& part, uint32_t ti, uint32_t k, bool owner, bool meets,
                                 const RowSpans* rows, uint32_t tag) {
  SplitSide& side = *side_;
  const bool spans = rows != nullptr;
  const PartKey key{static_cast<uint32_t>(f_.obj.index), ti, k};
  const bool ranks = needsOrder(f_.opt);
  if (owner) {
    if (ranks) side.keys.push_back(key);
    ScreenTriangleInfo here;
    ScreenTriangleInfo& info = f_.opt.triangles ? side.owned.emplace_back() : here;
    describeTriangle(f_.obj.index, ti, partXY(part), spans, info, f_.st);  // placed among the frame's later
    markDrawn(side.drawn, info);
    if (spans) f_.countRows(*rows);
  } else if (ranks) {
    side.foreign.push_back(key);
  }
  if (!spans) walkAhead(*setup_.desc, side.walk, owner);
  if (!meets) return;
  const bool colour_attrs = traits(part.method).attributes == Attributes::Colour;
  part.unit->draw(SpanTriangle{part.v, part.method, spans ? nullptr : &setup_, rows, setup_config_.raster(colour_attrs),
                               tag, spans ? nullptr : &side.walk, spans, side.rows});
}

// A part of a TwoThreads::AfterSetup method queued for the back end, which records it: set up
// here (false: dropped, not queued), or handed off. Setup's errors here name no tag (the back
// end gives the tags): the part is then handed off, for the back end to fail on with its tag,
// and SetupHandedOff thrown (drawTwoThreads).
bool SceneDrawer::queueSetUp(const Part& part, uint32_t ti, const SetupInput& in, DrawJob& job, uint8_t hand_off) {
  bool failed = false;
  if (hand_off == 0) {
    try {
      if (!setup_config_.run(in, part.method, job.colour_attrs, 0, job.rows, job.setup, job.spans)) return false;
    } catch (const std::invalid_argument&) {
      failed = true;
      hand_off = DrawJob::kFirstPart | DrawJob::kLastPart;
    }
  }
  job.set_up = hand_off == 0;
  job.mesh_parts = hand_off;
  if (!job.set_up) job.in = in;
  job.info.object = f_.obj.index;
  job.info.mesh_triangle = ti;
  const auto xy = partXY(part);
  for (size_t i = 0; i < 3; ++i) job.info.xy[i] = xy(i);
  queue_->push();
  if (failed) throw SetupHandedOff{};
  return true;
}

// A descriptor walked here, on the front end, for the back end to replay (Frame::replay), and
// counted as Frame::walk counts it: on this side, with the span engine's stream. On a side of a
// frame split by rows: for its rows, counted where count (the triangle's owner).
void SceneDrawer::walkAhead(const SpanDesc& d, RecordedWalk& w, bool count) {
  w.events.clear();
  // Each event built whole (an emplace_back() and then its fields cleared the event first, a
  // `rep stos` per row).
  auto fragment = [&w](int32_t x, int32_t y, const int64_t* attr) {
    w.events.push_back({false, x, y, 1, 1, {attr[0], attr[1], attr[2], attr[3]}, {}});
  };
  auto run = [&w](const RowRun& r) {
    w.events.push_back(
        {true, r.x0, r.y, r.dx, r.count, {r.a0[0], r.a0[1], r.a0[2], r.a0[3]}, {r.da[0], r.da[1], r.da[2], r.da[3]}});
  };
  const SpanWalk wk = walkSpanUnit(*f_.walker, d, fragment, run, f_.span.streamOrNull());
  if (count) f_.count(wk);
}

// The back end of a two-thread frame: its own frame (its own counts) and the front end's setup
// configurations, copied: in lines of their own, apart from what the front end writes.
struct alignas(64) BackEnd {
  RenderStats stats;
  const TriangleSetup setup;
  Frame f;
  std::vector<ScreenTriangleInfo>& triangles;  // the result's
  uint64_t drawn_before = 0;                   // stats.drawn before the handed-off mesh triangle
  // A handed-off triangle set up here, not in its slot: the front end reads the slots' setup
  // ahead (prefetchJobForWrite) while this side holds them.
  SetupResult setup_here;
  RowSpans rows_here;
  BackEnd(const Scene& scene, const RenderOptions& opt, SpanEngine& span, RenderResult& res, const SceneDrawer& front)
      : setup(front.triangleSetup()), f(scene, opt, span, res.fb, stats), triangles(res.triangles) {}
  // A triangle to draw: its tag and its setup or rows' spans.
  struct Drawn {
    uint32_t tag;
    const SetupResult* setup;
    const RowSpans* rows;
  };
  // A triangle of a TwoThreads::AfterSetup method, set up here if handed off, and recorded into
  // t: false when setup drops it.
  bool record(DrawJob& j, Drawn& t) {
    const uint32_t tag = static_cast<uint32_t>(triangles.size());
    bool spans = j.spans;
    if (!j.set_up) {
      if (j.mesh_parts & DrawJob::kFirstPart) drawn_before = stats.drawn;
      if (!setup.run(j.in, j.method, j.colour_attrs, tag, rows_here, setup_here, spans)) {
        if ((j.mesh_parts & DrawJob::kLastPart) && stats.drawn == drawn_before) ++stats.culled_no_pixel;
        return false;
      }
      t.setup = spans ? nullptr : &setup_here;
      t.rows = spans ? &rows_here : nullptr;
    } else if (!spans) {
      j.setup.desc->tag = tag;  // set up by the front end, which knows no tag
    }
    t.tag = recordTriangle(j.info.object, j.info.mesh_triangle, [&j](size_t i) { return j.info.xy[i]; }, spans,
                           triangles, stats, f.fb);
    return true;
  }
};

// The back end's jobs, in order, drawn by the units of its frame, until the end mark or the
// front end's abort.
void drawBackEnd(DrawQueue& q, BackEnd& b, const Scene& scene, const SpecEngines& engines) {
  Frame& f = b.f;
  for (;;) {
    DrawJob* j = q.next();
    if (j == nullptr) return;
    switch (j->kind) {
      case DrawJob::Kind::End:
        q.release();
        return;
      case DrawJob::Kind::BeginObject:
        j->transform.work(true);
        lightObject(f, scene, engines, j->object);
        for (const auto& u : f.units()) u.second->beginObject();
        break;
      case DrawJob::Kind::EndObject:
        for (const auto& u : f.units()) u.second->endObject();
        break;
      case DrawJob::Kind::Triangle: {
        // No vertices: the methods that split a frame draw from the setup alone (methods.h).
        const std::array<const PVertex*, 3> v = {nullptr, nullptr, nullptr};
        const bool ahead = traits(j->method).two_threads == TwoThreads::AfterWalk;
        BackEnd::Drawn t{j->tag, j->spans ? nullptr : &j->setup, j->spans ? &j->rows : nullptr};
        if (!ahead && !b.record(*j, t)) break;  // dropped by the back end's setup
        const RowShare share{rowsShared(j->method, f.obj) ? RowShare::Side::Back : RowShare::Side::All};
        if (t.rows != nullptr && !share.anyRow(*t.rows)) break;  // the front end's rows alone
        f.unit(j->method).draw(SpanTriangle{v, j->method, t.setup, t.rows, b.setup.raster(j->colour_attrs), t.tag,
                                            ahead && !j->spans ? &j->walk : nullptr, ahead && j->spans, share});
        break;
      }
    }
    q.release();
  }
}

// The frame on two threads: this one the front end (SceneDrawer with a queue), another the back
// end (drawBackEnd with a frame of its own, on the same buffers and span engine). Every pixel
// is written by one side, the back end, or for a triangle walked ahead the side whose rows it
// lies in (RowShare), in the order of one thread, after the back end has cleared what the frame
// before drew (clear: the front end waits for it before it draws); each side counts in its own
// RenderStats, summed after. The objects' specular-unit codings are made here first, so that
// the two sides' lightObject only read the units' memo of zero codes (SpecEngine::zeroCode).
void drawTwoThreads(const Scene& scene, SpanEngine& span, const SpecEngines& engines, Frame& front,
                    const ClearRect& clear, RenderResult& res, std::atomic<bool>& cleared) {
  for (size_t oi = 0; oi < scene.objects.size(); ++oi) lightObject(front, scene, engines, oi);
  BackThread& worker = BackThread::instance();
  const std::lock_guard<std::mutex> one_frame(worker.frame);
  DrawQueue& q = worker.queue;
  q.reset();
  SceneDrawer drawer(front, scene, engines, res, res.scratch.get().main, &q, &cleared);
  const auto back = std::make_unique<BackEnd>(scene, front.opt, span, res, drawer);
  back->f.unit(front.opt.method);  // made before the first object's beginObject, as the front's
  const std::function<void()> back_end = [&] {
    try {
      clearRect(res.fb, clear);  // while the front end transforms and sets up the first triangles
      cleared.store(true, std::memory_order_release);
      drawBackEnd(q, *back, scene, engines);
    } catch (...) {
      q.stop(std::current_exception());
    }
  };
  worker.start(back_end);
  try {
    for (size_t oi = 0; oi < scene.objects.size(); ++oi) drawer.drawObject(oi);
    q.slot().kind = DrawJob::Kind::End;
    q.push(true);
  } catch (const DrawQueue::ReaderStopped&) {
    // the back end's exception, below
  } catch (const SetupHandedOff&) {
    // The back end fails on the triangle handed off, or on one before it: its exception, below.
    try {
      q.slot().kind = DrawJob::Kind::End;
      q.push(true);
    } catch (const DrawQueue::ReaderStopped&) {
    }
    worker.wait();
    if (!q.error()) throw std::logic_error("render: a setup that failed on the front end passed on the back end");
  } catch (...) {
    q.abort();
    worker.wait();
    throw;
  }
  worker.wait();
  if (q.error()) std::rethrow_exception(q.error());
  res.stats += back->stats;
}

// drawTwoThreads, and on an error before the back end cleared the buffers (an object's lobe
// without its specular unit, say) the clear done here: the buffers are then as one thread
// leaves them, clear outside the drawn rectangle, which the next frame's clear relies on.
void renderTwoThreads(const Scene& scene, SpanEngine& span, const SpecEngines& engines, Frame& front,
                      const ClearRect& clear, RenderResult& res) {
  std::atomic<bool> cleared{false};  // set by the back end (the front end waits for it to draw)
  try {
    drawTwoThreads(scene, span, engines, front, clear, res, cleared);
  } catch (...) {
    if (!cleared) clearRect(res.fb, clear);
    throw;
  }
}

// Every object of the scene drawn on this thread: the whole frame, or a side's rows of it.
void drawScene(Frame& f, const Scene& scene, const SpecEngines& engines, RenderResult& res, DrawScratch& scratch,
               SplitSide* side = nullptr) {
  SceneDrawer drawer(f, scene, engines, res, scratch, nullptr, nullptr, side);
  for (size_t oi = 0; oi < scene.objects.size(); ++oi) drawer.drawObject(oi);
}

// A side of a frame split by rows: its rows cleared of what the frame before drew, then its
// rows of every object drawn.
void drawSide(const Scene& scene, const SpecEngines& engines, Frame& f, RenderResult& res, DrawScratch& scratch,
              SplitSide& side, const ClearRect& clear) {
  const auto t0 = std::chrono::steady_clock::now();
  ClearRect rows = clear;
  rows.y0 = std::max(clear.y0, side.rows.y0);
  rows.y1 = std::min(clear.y1, side.rows.y1 - 1);
  clearRect(res.fb, rows);
  drawScene(f, scene, engines, res, scratch, &side);
  side.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The next frame's split: where the two sides would take as long, each side's time spread evenly
// over its rows of the drawn rectangle [y0, y1], halfway from this frame's split (frames of a
// benchmark or an animation settle on it); the middle of [y0, y1] when this split lay outside.
int32_t nextSplit(const std::array<SplitSide, 2>& sides, int32_t y0, int32_t y1) {
  const int32_t split = sides[0].split();
  if (split <= y0 || split > y1) return (y0 + y1 + 1) / 2;
  const double top = sides[0].seconds / (split - y0), bottom = sides[1].seconds / (y1 + 1 - split);
  if (!(top > 0 && bottom > 0)) return split;
  const double even = (top * y0 + bottom * (y1 + 1)) / (top + bottom);
  return std::clamp(static_cast<int32_t>(std::lround(0.5 * (split + even))), y0 + 1, y1);
}

// The frame's index of each side's triangles (SplitSide::global): those it owns ranked among
// both sides' by their keys (PartKey order, one thread's), those it drew for the other side
// looked up there. Returns how many triangles the frame has.
size_t rankSides(std::array<SplitSide, 2>& sides) {
  for (SplitSide& s : sides) s.global.resize(s.keys.size() + s.foreign.size());
  size_t at[2] = {0, 0};
  const size_t n[2] = {sides[0].keys.size(), sides[1].keys.size()};
  for (uint32_t g = 0; at[0] < n[0] || at[1] < n[1]; ++g) {
    const size_t i = at[1] == n[1] || (at[0] < n[0] && sides[0].keys[at[0]] < sides[1].keys[at[1]]) ? 0 : 1;
    sides[i].global[at[i]++] = g;
  }
  for (size_t i = 0; i < 2; ++i) {
    SplitSide& s = sides[i];
    const SplitSide& owner = sides[1 - i];
    size_t k = 0;
    for (size_t j = 0; j < s.foreign.size(); ++j) {
      while (k < owner.keys.size() && owner.keys[k] < s.foreign[j]) ++k;
      if (k == owner.keys.size() || s.foreign[j] < owner.keys[k])
        throw std::logic_error("render: a triangle drawn by one side of a split frame was not recorded by the other");
      s.global[s.keys.size() + j] = owner.global[k];
    }
  }
  return n[0] + n[1];
}

// A side's triangles placed at their ranks in the frame's list (sized by then), by the side's
// own thread: the descriptions stay in the cache of the core that wrote them. (The calling
// thread reading the back thread's too passed their lines to its core and back every frame:
// docs/performance.md, "Two threads".)
void placeOwned(const SplitSide& s, std::vector<ScreenTriangleInfo>& triangles) {
  for (size_t j = 0; j < s.owned.size(); ++j) triangles[s.global[j]] = s.owned[j];
}

// The sides' rectangles and tags made the frame's: the rectangle their triangles drew (the
// same min and max as one thread's markDrawn in any order), and each side's tags in the
// triangle buffer (SplitSide::global).
void joinSides(const std::array<SplitSide, 2>& sides, Framebuffer& fb) {
  for (const SplitSide& s : sides) fb.markDrawn(s.drawn);
  if (fb.tri.empty()) return;
  for (const SplitSide& s : sides)
    for (int32_t y = std::max(s.rows.y0, fb.drawn_y0); y <= std::min(s.rows.y1 - 1, fb.drawn_y1); ++y)
      for (int32_t x = fb.drawn_x0; x <= fb.drawn_x1; ++x) {
        int32_t& tag = fb.tri[static_cast<size_t>(y) * static_cast<size_t>(fb.width) + static_cast<size_t>(x)];
        if (tag < 0) continue;
        const uint32_t t = static_cast<uint32_t>(tag);
        tag = static_cast<int32_t>(s.global[t >= SplitSide::kForeignTag ? s.keys.size() + (t - SplitSide::kForeignTag) : t]);
      }
}

// The frame on two threads split by rows (SplitSide): this thread the top side, the back
// thread the bottom, where the frame before found the two would take as long (nextSplit; the
// same bytes and counts wherever it splits). On an error on either side, the frame on one thread instead, from
// cleared buffers: its error, and its buffers as it leaves them.
void renderSplit(const Scene& scene, const RenderOptions& opt, SpanEngine& span, const SpecEngines& engines,
                 const ClearRect& clear, RenderResult& res) {
  RenderScratch& scratch = res.scratch.get();
  const int32_t H = scene.camera.height;
  if (scratch.split < 0 || scratch.split > H) scratch.split = H / 2;
  const int32_t split = opt.split_row >= 0 ? std::min(opt.split_row, H) : scratch.split;
  std::vector<std::unique_ptr<SplitObject>>& objects = scratch.split_objects;
  if (objects.size() < scene.objects.size()) objects.resize(scene.objects.size());
  for (size_t oi = 0; oi < scene.objects.size(); ++oi) {
    if (!objects[oi]) objects[oi] = std::make_unique<SplitObject>();
    objects[oi]->reset(scene.objects[oi].mesh.positions.size(), scene.objects[oi].mesh.triangles.size());
  }
  std::array<SplitSide, 2>& sides = scratch.sides;
  for (size_t i = 0; i < 2; ++i) {
    SplitSide& s = sides[i];
    s.objects = &objects;
    s.top = i == 0;
    s.H = H;
    s.rows.y0 = s.top ? 0 : split;
    s.rows.y1 = s.top ? split : H;
    s.keys.clear();
    s.owned.clear();
    s.foreign.clear();
    s.drawn.width = res.fb.width;
    s.drawn.height = res.fb.height;
    s.drawn.markNothingDrawn();
    s.stats = s.others = RenderStats{};
    s.error = nullptr;
  }
  Frame top(scene, opt, span, res.fb, res.stats);
  // The bottom side's frame in lines of its own, off this thread's stack.
  struct alignas(64) BottomFrame {
    Frame f;
  };
  const std::unique_ptr<BottomFrame> bottom(new BottomFrame{Frame(scene, opt, span, res.fb, sides[1].stats)});
  BackThread& worker = BackThread::instance();
  std::exception_ptr error;
  {
    const std::lock_guard<std::mutex> one_frame(worker.frame);
    const std::function<void()> draw = [&] {
      try {
        drawSide(scene, engines, bottom->f, res, scratch.second, sides[1], clear);
      } catch (...) {
        sides[1].error = std::current_exception();
      }
    };
    worker.start(draw);
    try {
      drawSide(scene, engines, top, res, scratch.main, sides[0], clear);
    } catch (...) {
      sides[0].error = std::current_exception();
    }
    worker.wait();
    // Once both sides have drawn, each places its own triangles in the frame's list.
    error = sides[0].error ? sides[0].error : sides[1].error;
    if (!error) try {
        const size_t n = needsOrder(opt) ? rankSides(sides) : 0;
        res.triangles.resize(opt.triangles ? n : 0);  // kept from the frame before: mostly nothing to fill
      } catch (...) {
        error = std::current_exception();
      }
    if (!error && opt.triangles) {
      const std::function<void()> place = [&] { placeOwned(sides[1], res.triangles); };
      worker.start(place);
      placeOwned(sides[0], res.triangles);
      worker.wait();
    }
  }
  if (error) {
    // The sides marked nothing drawn (joinSides does), so the framebuffer's drawn rectangle is
    // still prepareClear's empty one, as one thread starts with.
    res.stats = RenderStats{};
    res.triangles.clear();
    clearRect(res.fb, ClearRect{0, 0, res.fb.width - 1, res.fb.height - 1, traits(opt.method).exact});
    Frame one(scene, opt, span, res.fb, res.stats);
    drawScene(one, scene, engines, res, scratch.main);
    std::rethrow_exception(error);  // one thread drew it
  }
  res.stats += sides[1].stats;
  joinSides(sides, res.fb);
  if (res.fb.drawn_y0 <= res.fb.drawn_y1) scratch.split = nextSplit(sides, res.fb.drawn_y0, res.fb.drawn_y1);
}

}  // namespace


// SplitSide: RenderOptions::split, and nothing counted across triangles in their order: no device
// lobe (the specular unit's cycles, its engine's memo), the paper's span unit (not the
// full-rate unit's stream). A lobe or material that does not parse: not split, for one
// thread's error.
bool splitsByRows(const Scene& scene, const RenderOptions& opt, SpanEngine& span) {
  using Split = RenderOptions::Split;
  if (opt.split == Split::FrontBack || span.walker() == nullptr || span.streamOrNull() != nullptr) return false;
  try {
    return deviceLobesUsed(scene, opt).empty();
  } catch (const std::exception&) {
    return false;
  }
}

RenderStats& RenderStats::operator+=(const RenderStats& o) {
  triangles += o.triangles;
  culled_back += o.culled_back;
  culled_outside += o.culled_outside;
  culled_no_pixel += o.culled_no_pixel;
  clipped += o.clipped;
  drawn += o.drawn;
  row_spans += o.row_spans;
  fragments += o.fragments;
  pixels_covered += o.pixels_covered;
  span_cycles += o.span_cycles;
  spec_cycles += o.spec_cycles;
  spec_evaluations += o.spec_evaluations;
  spec_at_zero += o.spec_at_zero;
  depth_rejected += o.depth_rejected;
  divisions += o.divisions;
  split_parts += o.split_parts;
  normalisations += o.normalisations;
  adaptive_gouraud += o.adaptive_gouraud;
  adaptive_phong += o.adaptive_phong;
  return *this;
}

int64_t SpecEngine::zeroCode(uint32_t shin) {
  constexpr int64_t kUnknown = -2;
  const SpecUnitModel* m = model();
  if (m == nullptr) {
    if (!table_model_) {
      const PromTable& t = table();
      table_model_ = std::make_unique<SpecUnitModel>(t.unit, t.words, t.seg_words);
    }
    m = table_model_.get();
  }
  if (shin >= zero_.size()) zero_.resize(std::max<size_t>(shin + 1, m->prom().size()), kUnknown);
  if (zero_[shin] == kUnknown) zero_[shin] = m->zeroCode(shin);
  return zero_[shin];
}

uint64_t ModelSpecEngine::evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) {
  out.resize(in.size());
  for (size_t i = 0; i < in.size(); ++i) {
    unit_.checkCosine(in[i].shin, in[i].cos);
    out[i] = in[i].cos <= zeroCode(in[i].shin) ? std::array<uint32_t, 3>{} : unit_.evaluate(in[i].shin, in[i].cos, in[i].light).rgb;
  }
  return batchCycles(in.size(), unit_.params().latency());
}

std::vector<Lobe> deviceLobesUsed(const Scene& scene, const RenderOptions& opt) {
  std::vector<Lobe> used;
  if (traits(opt.method).exact) return used;  // the reference uses the exact lobes
  for (const SceneObject& o : scene.objects) {
    const Lobe l = parseLobe(opt.brdf.empty() ? scene.materials.at(static_cast<size_t>(o.material)).brdf : opt.brdf);
    if (isDeviceLobe(l) && std::find(used.begin(), used.end(), l) == used.end()) used.push_back(l);
  }
  return used;
}

Image frameImage(const Framebuffer& fb) {
  Image img(fb.width, fb.height);
  img.rgb = fb.rgb;
  return img;
}

PixelMask coveredPixels(const Framebuffer& fb) {
  PixelMask m(fb.width, fb.height);
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x)
      if (fb.covered(x, y)) m.set(x, y);
  return m;
}

ImageF exactImage(const Framebuffer& reference) {
  ImageF img(reference.width, reference.height, reference.lsb);
  for (double& v : img.rgb) v = std::clamp(v, 0.0, 255.0);
  return img;
}

RenderResult render(const Scene& scene, const RenderOptions& opt, SpanEngine& span, const SpecEngines& engines) {
  RenderResult res;
  render(scene, opt, span, engines, res);
  return res;
}

void render(const Scene& scene, const RenderOptions& opt, SpanEngine& span, const SpecEngines& engines, RenderResult& res) {
  const auto t0 = std::chrono::steady_clock::now();
  if (opt.phong_widths) {
    if (opt.method != Method::PhongFixed)
      throw std::invalid_argument(
          fmt::format("render: datapath widths apply to phong-fixed only, not to {}", toString(opt.method)));
    opt.phong_widths->validate();
  }
  res.stats = RenderStats{};
  if (opt.threads != 1 && opt.threads != 2)
    throw std::invalid_argument(fmt::format("render: threads {}: 1 or 2", opt.threads));
  if (opt.threads == 2 && traits(opt.method).two_threads == TwoThreads::No)
    throw std::invalid_argument(fmt::format("render: {} runs on one thread (two: {})", toString(opt.method),
                                            twoThreadMethods()));
  if (opt.threads == 2 && span.walker() == nullptr)
    throw std::invalid_argument("render: two threads need the model's span unit, not the RTL's");
  const ClearRect clear =
      prepareClear(res.fb, scene.camera.width, scene.camera.height, traits(opt.method).exact, opt.tags);
  span.beginFrame();
  // Split::Auto chooses by the frames' times (SplitChoice); its first frame by rows, for every
  // method the faster way on most of the spheres measured (docs/performance.md).
  const bool may_split = opt.threads == 2 && splitsByRows(scene, opt, span);
  const bool measured = may_split && opt.split == RenderOptions::Split::Auto;
  SplitChoice& choice = res.scratch.get().choice;
  res.split_by_rows = measured ? choice.next(true) : may_split;
  if (res.split_by_rows) {
    renderSplit(scene, opt, span, engines, clear, res);  // into the list the frame before left
  } else {
    res.triangles.clear();
    Frame frame(scene, opt, span, res.fb, res.stats);
    if (opt.threads == 1) {
      clearRect(res.fb, clear);
      drawScene(frame, scene, engines, res, res.scratch.get().main);
    } else {
      renderTwoThreads(scene, span, engines, frame, clear, res);
    }
    // Here a triangle's tag is its index in the list, so the list is made either way. (Left
    // out, with a count for the tags, one thread's frame took as long: docs/performance.md.)
    if (!opt.triangles) res.triangles.clear();
  }
  span.endFrame();
  res.stats.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (measured) choice.record(res.stats.ms);
}

}  // namespace shd
