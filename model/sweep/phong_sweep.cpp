#include "sweep/phong_sweep.h"

#include <algorithm>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>

#include <fmt/format.h>

#include "image/image.h"
#include "image/metrics.h"
#include "io/files.h"
#include "render/fixed_widths.h"
#include "render/lobe_units.h"
#include "render/render.h"
#include "scene/scene.h"
#include "sweep/area.h"
#include "sweep/span_sweep.h"

namespace shd {

namespace {

// The scene file's text and that of every mesh file it reads (builtin meshes are code), hashed:
// what the scene's images depend on besides the program.
std::string sceneHash(const std::string& file, const Scene& scene) {
  std::string text = readInputFile(file, kMaxSceneFileBytes);
  std::set<std::string> meshes;
  for (const SceneObject& o : scene.objects)
    if (o.source.compare(0, 8, "builtin:") != 0 && meshes.insert(o.source).second)
      text += "\n" + readInputFile(o.source, kMaxMeshFileBytes);
  return textHash(text);
}

Scene loadNamedScene(const std::string& name, const std::string& file) {
  try {
    return loadScene(file);
  } catch (const SceneError& e) {
    throw std::invalid_argument(fmt::format("scene \"{}\": {}", name, e.what()));
  }
}

RenderResult renderWith(const Scene& scene, Method method, const std::optional<PhongWidths>& widths,
                        const LobeConfigs& lobes) {
  RenderOptions o;
  o.method = method;
  o.phong_widths = widths;
  LobeEngines engines = modelLobeEngines(scene, o, lobes);  // per render: the memo is not shared
  ModelSpanEngine span(SpanParams{});
  return render(scene, o, span, engines.view);
}

// A scene's images that every point compares with, rendered once per unit.
struct SceneImages {
  std::string name;
  Scene scene;
  ImageF reference;  // the exact colour, clamped to 0..255
  Image phong, fixed;
  PixelMask covered;  // by the reference, phong and phong-fixed
};

// The unit's scenes, loaded (and their hashes checked against the plan's) on first use.
class PhongScenes {
 public:
  PhongScenes(std::vector<std::string> names, nlohmann::json hashes, LobeConfigs lobes)
      : names_(std::move(names)), hashes_(std::move(hashes)), lobes_(std::move(lobes)) {}
  const std::vector<SceneImages>& get() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (scenes_.empty()) load();
    return scenes_;
  }
  const LobeConfigs& lobes() const { return lobes_; }

 private:
  void load();
  std::mutex mutex_;
  std::vector<std::string> names_;
  nlohmann::json hashes_;
  LobeConfigs lobes_;
  std::vector<SceneImages> scenes_;
};

void PhongScenes::load() {
  std::vector<SceneImages> loaded;
  for (const std::string& name : names_) {
    const std::string file = sweepSceneFile(name);
    SceneImages s;
    s.name = name;
    s.scene = loadNamedScene(name, file);
    const std::string hash = sceneHash(file, s.scene);
    if (hash != hashes_.at(name).get<std::string>())
      throw std::invalid_argument(fmt::format("scene \"{}\" ({}) changed since the sweep was planned (hash {}, the "
                                              "plan's {}): start a new sweep",
                                              name, file, hash, hashes_.at(name).get<std::string>()));
    const RenderResult ref = renderWith(s.scene, Method::Reference, std::nullopt, lobes_);
    const RenderResult phong = renderWith(s.scene, Method::Phong, std::nullopt, lobes_);
    const RenderResult fixed = renderWith(s.scene, Method::PhongFixed, std::nullopt, lobes_);
    s.reference = exactImage(ref.fb);
    s.phong = frameImage(phong.fb);
    s.fixed = frameImage(fixed.fb);
    s.covered = intersect(intersect(coveredPixels(ref.fb), coveredPixels(phong.fb)), coveredPixels(fixed.fb));
    loaded.push_back(std::move(s));
  }
  scenes_ = std::move(loaded);
}

// The figures of one scene at one point (the file comment of phong_sweep.h).
nlohmann::json sceneError(const SceneImages& s, const RenderResult& res) {
  const Image img = frameImage(res.fb);
  const PixelMask covered = intersect(s.covered, coveredPixels(res.fb));
  const ImageMetrics total = imageMetrics(img, s.reference, covered);
  const ImageMetrics dp = imageMetrics(img, s.phong, covered);
  const ImageMetrics def = imageMetrics(img, s.fixed, covered);
  return {{"max_abs_lsb", total.max_abs_lsb},
          {"worst_x", total.worst_x},
          {"worst_y", total.worst_y},
          {"rmse_lsb", total.rmse_lsb},
          {"datapath_max_lsb", dp.max_abs_lsb},
          {"datapath_worst_x", dp.worst_x},
          {"datapath_worst_y", dp.worst_y},
          {"datapath_rmse_lsb", dp.rmse_lsb},
          {"default_max_lsb", def.max_abs_lsb}};
}

nlohmann::json evaluatePhongPoint(uint64_t index, const PhongWidths& w, PhongScenes& scenes) {
  nlohmann::json per_scene = nlohmann::json::object();
  double dp_max = 0, dp_rmse = 0, total_max = 0;
  for (const SceneImages& s : scenes.get()) {
    const nlohmann::json e = sceneError(s, renderWith(s.scene, Method::PhongFixed, w, scenes.lobes()));
    dp_max = std::max(dp_max, e.at("datapath_max_lsb").get<double>());
    dp_rmse = std::max(dp_rmse, e.at("datapath_rmse_lsb").get<double>());
    total_max = std::max(total_max, e.at("max_abs_lsb").get<double>());
    per_scene[s.name] = e;
  }
  nlohmann::json j;
  j["index"] = index;
  j["hash"] = textHash(w.toJson().dump());
  j["widths"] = w.toJson();
  j["error"] = {{"datapath_max_lsb", dp_max}, {"datapath_rmse_lsb", dp_rmse}, {"max_abs_lsb", total_max},
                {"scenes", per_scene}};
  j["rom_bits"] = phongRomBits(w);
  j["mul_bits"] = phongMulBits(w);
  return j;
}

// The base widths with the point's values, validated (the bare message of the derivation).
PhongWidths widthsAt(const PhongWidths& base, const PointValues& values) {
  PhongWidths w = base;
  for (const auto& [name, value] : values) w.at(name) = value;
  w.validate();
  return w;
}

}  // namespace

PhongWidths phongPointWidths(const PhongWidths& base, const PointValues& values) {
  try {
    return widthsAt(base, values);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("point {}: {}", describePoint(values), e.what()));
  }
}

namespace {
// The seed table's word: the bit length of its largest entry.
int64_t seedWordBits(const PhongWidths& w) {
  const std::shared_ptr<const std::vector<uint32_t>> seeds = rsqrtSeedTable(w.RsqrtSeedBits, w.RsqrtSeedFracBits);
  return 32 - __builtin_clz(*std::max_element(seeds->begin(), seeds->end()) | 1);
}
}  // namespace

int64_t phongRomBits(const PhongWidths& w) {
  return (int64_t{1} << w.RsqrtSeedBits) * seedWordBits(w) +
         ((int64_t{1} << w.LobeCosBits) + 1) * (w.LobeCodeBits + w.LobeIntBits);
}

int64_t phongMulBits(const PhongWidths& w) {
  const int64_t n = w.NormalFracBits + 2, u = w.UnitFracBits + 2, nf = w.NewtonFracBits;
  const int64_t factor = w.FactorIntBits + w.ColourFracBits, word = w.LobeCodeBits + w.LobeIntBits;
  int64_t r = seedWordBits(w);  // r's bits into the step
  int64_t bits = 6 * n * u;     // N.L, N.H
  for (int k = 0; k < w.NewtonSteps; ++k) {
    bits += r * r + nf * 2 * r + r * (nf + 2);  // r r, m (r^2), r (3 - m r^2)
    r = nf + 2;
  }
  bits += 2 * (w.NormalFracBits + w.UnitFracBits + 2) * (nf + 2);  // the two cosines' scaling
  bits += (word + 1) * (w.CosFracBits - w.LobeCosBits);             // lobe interpolation
  bits += 3 * factor * (w.CosFracBits + 1) + 3 * factor * word;     // diffuse, specular
  return bits;
}

nlohmann::json phongSweepBase(const std::vector<std::string>& scenes) {
  if (scenes.empty()) throw std::invalid_argument("a phong sweep needs at least one scene");
  nlohmann::json hashes = nlohmann::json::object();
  for (const std::string& name : scenes) {
    if (hashes.contains(name)) throw std::invalid_argument(fmt::format("scene \"{}\" named twice", name));
    const std::string file = sweepSceneFile(name);
    hashes[name] = sceneHash(file, loadNamedScene(name, file));
  }
  const LobeConfigs lobes;
  return {{"unit", "phong"},
          {"scenes", scenes},
          {"scene_hashes", hashes},
          {"widths", PhongWidths{}.toJson()},
          {"lobe_configs", {{"quadratic", lobes.quadratic}, {"cubic", lobes.cubic}}}};
}

SweepUnit phongSweepUnit(const nlohmann::json& base_json) {
  const PhongWidths base = PhongWidths::fromJson(base_json.at("widths"), "the sweep's base");
  const std::vector<std::string> names = base_json.at("scenes").get<std::vector<std::string>>();
  std::string joined;
  for (const std::string& n : names) joined += (joined.empty() ? "" : ",") + n;
  LobeConfigs lobes;
  lobes.quadratic = base_json.at("lobe_configs").at("quadratic").get<std::string>();
  lobes.cubic = base_json.at("lobe_configs").at("cubic").get<std::string>();
  auto scenes = std::make_shared<PhongScenes>(names, base_json.at("scene_hashes"), lobes);
  SweepUnit u;
  u.name = "phong";
  u.base = base_json;
  u.base_options = "--scene " + joined;
  u.params = PhongWidths::names();
  u.params_member = "widths";
  u.front_error = "datapath_max_lsb";
  u.front_costs = {"rom_bits", "mul_bits"};
  u.validate = [base](const Grid& grid) {
    for (uint64_t k = 0; k < grid.size(); ++k) {
      const PointValues values = grid.point(k);
      try {
        widthsAt(base, values);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(fmt::format("point {} ({}): {}", k, describePoint(values), e.what()));
      }
    }
  };
  u.evaluate = [base, scenes](uint64_t index, const PointValues& values) {
    return evaluatePhongPoint(index, phongPointWidths(base, values), *scenes);
  };
  // No RTL of this datapath: no area, no configuration to write. Its widths: every parameter
  // but NewtonSteps, a count.
  for (const std::string& n : u.params)
    if (n != "NewtonSteps") u.widths.push_back(n);
  return u;
}

}  // namespace shd
