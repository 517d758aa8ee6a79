#include "cli/report_measure.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include <fmt/format.h>

#include "cli/progress.h"
#include "cli/render_common.h"
#include "image/compose.h"
#include "image/metrics.h"
#include "render/methods.h"
#include "sweep/grid.h"

namespace fs = std::filesystem;

namespace shd::cli {

namespace {

constexpr int kThumbSize = 128;          // the longer side of a contact sheet's image, at most
constexpr Rgb kThumbGap{255, 255, 255};  // between an image and its heat map

// Why no method is rendered with lobe group g on this scene ("" if they are): a lobe matters
// only where a light meets a specular material, and "material" repeats a brdf that every
// object's material has.
std::string groupSkipReason(const Scene& sc, const LobeGroup& g) {
  std::set<std::string> brdfs;
  bool specular = false;
  for (const SceneObject& o : sc.objects) {
    const Material& m = sc.materials.at(static_cast<size_t>(o.material));
    brdfs.insert(m.brdf);
    specular = specular || m.ks > 0;
  }
  if (g.name == "material")
    return brdfs.size() == 1 && !sc.lights.empty() && specular
               ? fmt::format("every object's material has the {} lobe: these are the rows of {}", *brdfs.begin(),
                             *brdfs.begin())
               : "";
  if (sc.lights.empty())
    return "the scene has no lights: no lobe is evaluated, and every lobe gives the image of the material rows";
  if (!specular)
    return "no object's material has a specular part (ks = 0): every lobe gives the image of the material rows";
  return "";
}

// Why method m does not apply with lobe group g ("" if it does): the exact methods evaluate a
// device lobe as its exact Blinn lobe, without the specular unit (render/methods.h).
std::string cellSkipReason(Method m, const LobeGroup& g) {
  if (traits(m).exact && !g.brdf.empty() && isDeviceLobe(parseLobe(g.brdf)))
    return fmt::format("{} evaluates every lobe exactly, without the specular unit: a device lobe is its exact Blinn "
                       "lobe, these are the rows of {}/blinn",
                       toString(m), toString(m));
  return "";
}

// The files of method m with lobe group g: images/<method>_<lobe>.png and its heat map's.
void nameCellFiles(Method m, const LobeGroup& g, CellImages& c) {
  const std::string stem = fmt::format("images/{}_{}", toString(m), g.name);
  c.image_file = stem + ".png";
  c.heat_file = stem + "_error.png";
}

// The image and its heat map, encoded, and their thumbnail for the contact sheet.
CellImages cellImages(Method m, const LobeGroup& g, const Image& img, const Image& heat) {
  CellImages c;
  nameCellFiles(m, g, c);
  c.image_png = encodePng(c.image_file, img);
  c.heat_png = encodePng(c.heat_file, heat);
  const int factor = std::max(1, (std::max(img.width, img.height) + kThumbSize - 1) / kThumbSize);
  c.thumb = stackVertical(downscaleBox(img, factor), downscaleBox(heat, factor), 2, kThumbGap);
  return c;
}

// A method's image of a lobe against the lobe's reference: the metrics and the files.
struct CellComparison {
  ImageMetrics all, highlight;
  CellImages files;
};

// A lobe's reference, and the distinct images its methods drew so far, each as
// compareWithReference reads it (the image and the pixels covered) with what it gave.
struct LobeImages {
  struct Drawn {
    Image image;
    PixelMask covered;
    CellComparison comparison;
  };
  ReferenceImage reference;
  std::vector<Drawn> drawn;
};

// Method m's image and covered pixels against the lobe's reference; or, when an earlier method
// of the lobe drew the same image over the same pixels (adaptive choosing Phong for every
// triangle, say), that method's comparison: the same metrics and PNG bytes under m's file names,
// neither measured nor encoded again.
CellComparison compareCell(Method m, const LobeGroup& g, const Image& img, const PixelMask& covered, double heat_scale,
                           LobeImages& lobe) {
  const auto same = std::find_if(lobe.drawn.begin(), lobe.drawn.end(), [&](const LobeImages::Drawn& d) {
    return d.image == img && d.covered.bits == covered.bits;
  });
  if (same != lobe.drawn.end()) {
    CellComparison c = same->comparison;
    nameCellFiles(m, g, c.files);
    return c;
  }
  const Comparison c = compareWithReference(img, covered, lobe.reference, heat_scale);
  lobe.drawn.push_back({img, covered, {c.all, c.highlight, cellImages(m, g, img, c.heat)}});
  return lobe.drawn.back().comparison;
}

// What every mode's row of a method and lobe holds besides its own measurements.
nlohmann::json cellBase(Method m, const LobeGroup& g, const std::vector<std::string>& spec_configs,
                        const CellComparison& c) {
  return {{"method", toString(m)},         {"lobe", g.name},
          {"spec_configs", spec_configs},  {"image", c.files.image_file},
          {"heat_map", c.files.heat_file}, {"metrics", toJson(c.all)},
          {"highlight", toJson(c.highlight)}};
}

// The rows of one method and lobe, one per mode: rendered by the model (s.frames frames, the
// median time), the image compared with the first mode's, and with --rtl by the verilated units.
// The renderer's std::invalid_argument on the first frame means the combination does not apply.
nlohmann::json measureCell(const ReportSetup& s, Method m, size_t gi, LobeImages& lobe, Progress& progress,
                           Measured& out) {
  const Scene& sc = *s.scene;
  const LobeGroup& g = out.groups[gi];
  RenderOptions ro;
  ro.method = m;
  ro.brdf = g.brdf;
  // The triangle buffer and list: for checkRtlFrame's report of the first differing pixel.
  ro.tags = ro.triangles = s.rtl;
  LobeConfigs lobes = s.lobes;
  if (!g.unit.empty()) lobes.quadratic = g.unit;
  std::vector<std::string> spec_configs;
  for (Lobe l : deviceLobesUsed(sc, ro)) spec_configs.push_back(lobeConfigArg(lobes, l).name);
  nlohmann::json rows = nlohmann::json::array();
  Image first;
  nlohmann::json base;
  for (const SpanUnitConfig& mode : s.modes) {
    Engines model = makeEngines(sc, ro, mode, lobes, false, s.tmp, s.fail_dir);
    const RenderResult res = render(sc, ro, *model.span, model.view);
    RenderResult scratch;
    const double ms = medianFrameMs(sc, ro, model, res, s.frames, scratch);
    const Image img = frameImage(res.fb);
    if (rows.empty()) {
      CellComparison c = compareCell(m, g, img, coveredPixels(res.fb), s.heat_scale, lobe);
      base = cellBase(m, g, spec_configs, c);
      out.images[{gi, static_cast<size_t>(m)}] = std::move(c.files);
      first = img;
    } else {
      ++out.mode_comparisons;
    }
    const bool exact = traits(m).exact;  // drawn without the span unit: no hardware time
    const RenderStats& st = res.stats;
    nlohmann::json row = base;
    row.update({{"mode", mode.name},
                {"span_config", mode.name},
                {"ms", ms},
                {"frames", s.frames},
                {"span_cycles", exact ? nlohmann::json() : nlohmann::json(st.span_cycles)},
                {"spec_cycles", spec_configs.empty() ? nlohmann::json() : nlohmann::json(st.spec_cycles)},
                {"total_cycles", exact ? nlohmann::json() : nlohmann::json(st.span_cycles + st.spec_cycles)},
                {"spec_evaluations", st.spec_evaluations},
                {"counts", frameCounts(st)},
                {"image_equals_first_mode", img == first}});
    if (img != first)
      out.failures.push_back(fmt::format("{}/{}: the image in mode {} differs from mode {}'s in {} pixels", toString(m),
                                         g.name, mode.name, s.modes.front().name, differingPixels(first, img).count()));
    if (s.rtl) {
      Engines hw = makeEngines(sc, ro, mode, lobes, true, s.tmp, s.fail_dir);
      const RenderResult hres = render(sc, ro, *hw.span, hw.view);
      fs::remove_all(s.tmp);
      const RtlCheck check = checkRtlFrame(sc, res, hres);
      row["rtl"] = check.json;
      row["rtl"]["pixel_mismatches"] = check.mismatches;
      if (!check.ok())
        out.failures.push_back(fmt::format("{}/{} {}: the verilated units differ from the model: {}{}", toString(m),
                                           g.name, mode.name, check.first_mismatch,
                                           check.json["cycles_equal"].get<bool>() ? "" : " (cycles differ)"));
    }
    rows.push_back(std::move(row));
    progress.update(static_cast<double>(++out.renders_done), static_cast<double>(out.renders_total), "renders");
  }
  for (const std::string& cfg : spec_configs)
    if (std::find(out.spec_configs.begin(), out.spec_configs.end(), cfg) == out.spec_configs.end())
      out.spec_configs.push_back(cfg);
  return rows;
}

}  // namespace

std::vector<LobeGroup> reportLobeGroups(const std::vector<std::string>& alt_units) {
  std::vector<LobeGroup> g = {{"material", "", ""}};
  for (int l = static_cast<int>(Lobe::Phong); l <= static_cast<int>(Lobe::Pow); ++l)
    g.push_back({toString(static_cast<Lobe>(l)), toString(static_cast<Lobe>(l)), ""});
  for (const std::string& u : alt_units) g.push_back({unitLobeGroup(specConfig(u).name), toString(Lobe::Quadratic), u});
  return g;
}

Measured measureReport(const ReportSetup& s) {
  const Scene& sc = *s.scene;
  Measured out;
  out.groups = reportLobeGroups(s.alt_units);
  out.methods = allMethods();
  std::vector<std::string> group_skip;
  for (const LobeGroup& g : out.groups) group_skip.push_back(groupSkipReason(sc, g));
  if (!group_skip.back().empty())  // a scene whose lobes change nothing (the reason is the same for every brdf)
    out.warnings.push_back(fmt::format("{}: {}; the report has only the material rows", sc.name, group_skip.back()));
  for (size_t gi = 0; gi < out.groups.size(); ++gi)
    if (group_skip[gi].empty())
      for (Method m : out.methods)
        if (cellSkipReason(m, out.groups[gi]).empty()) out.renders_total += s.modes.size();
  Progress progress(fmt::format("report {}", sc.name), !s.quiet);
  std::string first_refusal;
  for (size_t gi = 0; gi < out.groups.size(); ++gi) {
    const LobeGroup& g = out.groups[gi];
    if (!group_skip[gi].empty()) {
      out.skipped.push_back({{"method", "*"}, {"lobe", g.name}, {"why", group_skip[gi]}});
      continue;
    }
    RenderOptions ro;
    ro.brdf = g.brdf;
    LobeImages lobe{referenceImage(renderReference(sc, ro), s.highlight_lsb), {}};
    for (Method m : out.methods) {
      const std::string why = cellSkipReason(m, g);
      if (!why.empty()) {
        out.skipped.push_back({{"method", toString(m)}, {"lobe", g.name}, {"why", why}});
        continue;
      }
      const size_t done_before = out.renders_done;
      try {
        for (nlohmann::json& row : measureCell(s, m, gi, lobe, progress, out)) out.rows.push_back(std::move(row));
      } catch (const std::invalid_argument& e) {  // the renderer refuses the combination
        out.skipped.push_back({{"method", toString(m)}, {"lobe", g.name}, {"why", fmt::format("not rendered: {}", e.what())}});
        if (first_refusal.empty()) first_refusal = e.what();
        out.images.erase({gi, static_cast<size_t>(m)});
        out.renders_done = done_before + s.modes.size();
      }
    }
  }
  if (out.rows.empty())
    throw std::invalid_argument(fmt::format("{}: no method and lobe could be rendered ({})", sc.name, first_refusal));
  return out;
}

std::string sceneContentHash(const Scene& sc) {
  // Every value in hexadecimal floating point (exact), in a fixed order.
  std::string t = fmt::format("camera {:a} {:a} {:a} {:a} {:a} {:a} {:a} {} {} {:a}\nambient {:a} {:a} {:a}\n",
                              sc.camera.eye.x, sc.camera.eye.y, sc.camera.eye.z, sc.camera.target.x,
                              sc.camera.target.y, sc.camera.target.z, sc.camera.px_per_unit, sc.camera.width,
                              sc.camera.height, sc.camera.z_near, sc.ambient.x, sc.ambient.y, sc.ambient.z);
  auto vec = [&t](Vec3 v) { t += fmt::format(" {:a} {:a} {:a}", v.x, v.y, v.z); };
  for (const Light& l : sc.lights) {
    t += l.kind == Light::Kind::Point ? "light point" : "light directional";
    vec(l.direction);
    vec(l.position);
    vec(l.colour);
    t += "\n";
  }
  for (const Material& m : sc.materials) {
    t += fmt::format("material {} {} {:a} {:a} {:a} {:a} {:a}", m.name, m.brdf, m.kd, m.ks, m.shininess, m.roughness,
                     m.f0);
    vec(m.colour);
    t += "\n";
  }
  for (const SceneObject& o : sc.objects) {
    t += fmt::format("object {} material {}", o.name, o.material);
    for (const auto& row : o.transform.m)
      for (double v : row) t += fmt::format(" {:a}", v);
    t += fmt::format("\nmesh {} {} {}\n", o.mesh.positions.size(), o.mesh.normals.size(), o.mesh.triangles.size());
    for (size_t i = 0; i < o.mesh.positions.size(); ++i) vec(o.mesh.positions[i]);
    for (size_t i = 0; i < o.mesh.normals.size(); ++i) vec(o.mesh.normals[i]);
    for (const auto& tri : o.mesh.triangles) t += fmt::format(" {} {} {}", tri[0], tri[1], tri[2]);
    t += "\n";
  }
  return textHash(t);
}

}  // namespace shd::cli
