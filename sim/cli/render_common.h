// What `shadesim render` and `shadesim report` share: the engines of a frame (the models or the
// verilated units), the image against the double-precision reference (metrics, highlight, heat
// map), the RTL-in-the-loop frame against the model's, and the statistics of a frame as JSON.
// One implementation, so that a report's figures are the figures `render --json` gives.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/registry.h"
#include "image/image.h"
#include "image/metrics.h"
#include "render/lobe_units.h"
#include "render/render.h"
#include "scene/scene.h"

namespace shd::cli {

// The configuration of a device lobe; its std::invalid_argument an ArgError naming the option
// (--quadratic-config or --cubic-config).
SpecUnitConfig lobeConfigArg(const LobeConfigs& lobes, Lobe l);

// The PROM table of a specular configuration (buildPromTable of its "prom" and "rtl"), built once
// per process and kept: a report makes the engines of every row, and the fit (the piecewise
// kind's minimax segments above all) would otherwise be repeated for each method and mode.
const PromTable& promTable(const SpecUnitConfig& cfg);

// The engines of one path (model or RTL) for the device lobes the scene uses.
struct Engines {
  std::unique_ptr<SpanEngine> span;
  std::vector<std::unique_ptr<SpecEngine>> spec;
  SpecEngines view;
};
// with_rtl: the verilated units (the configurations must be verilated: requireVerilated), the
// PROMs written into `tmp` (created), a disagreement with the model saved into fail_dir.
Engines makeEngines(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& span, const LobeConfigs& lobes,
                    bool with_rtl, const std::filesystem::path& tmp, const std::string& fail_dir);

// The reference frame of these options: the same scene and lobes, per pixel in double precision
// (Method::Reference through a serial span engine, which it does not use for pixels).
RenderResult renderReference(const Scene& sc, const RenderOptions& ro);

// What an image is measured against, taken from the reference frame once: its exact colour
// clamped to [0, 255] (exactImage), the pixels it covers and the highlight (the pixels whose
// specular part exceeds highlight_lsb). A report compares every method of a lobe with the same
// reference, so these are made once per lobe, not once per method. `ref` is taken over (its
// specular part is moved, not copied).
struct ReferenceImage {
  ImageF exact;
  PixelMask covered, highlight;
};
ReferenceImage referenceImage(RenderResult ref, double highlight_lsb);

// A frame's image and the pixels it covers (frameImage, coveredPixels) against the reference:
// metrics over the pixels both cover and over the highlight among them, and the heat map of the
// error (white at heat_scale LSBs). The reference as shown is roundToUnorm8(ref.exact).
struct Comparison {
  ImageMetrics all, highlight;
  Image heat;
};
Comparison compareWithReference(const Image& img, const PixelMask& covered, const ReferenceImage& ref,
                                double heat_scale);

// A frame rendered with the verilated units against the model's: the pixels that differ, the
// first of them with the triangles that wrote it, and {"ms", "span_cycles", "spec_cycles",
// "cycles_equal"}.
struct RtlCheck {
  nlohmann::json json;
  uint64_t mismatches = 0;
  std::string first_mismatch;
  bool ok() const { return mismatches == 0 && json["cycles_equal"].get<bool>(); }
};
RtlCheck checkRtlFrame(const Scene& sc, const RenderResult& model, const RenderResult& rtl);

// The counts of a frame: {"triangles", "culled" (and its parts "culled_back", "culled_outside",
// "culled_no_pixel"), "clipped", "drawn", "fragments",
// "pixels_covered", "cycles" (span unit), "spec_cycles", "spec_evaluations", "spec_at_zero",
// "depth_rejected", "divisions", "split_parts", "normalisations", "adaptive_gouraud",
// "adaptive_phong"} (RenderStats).
nlohmann::json frameCounts(const RenderStats& st);

// A frame's model time: `first` (already rendered) and frames - 1 more into `scratch`; the
// median of the frames' ms (render --bench).
double medianFrameMs(const Scene& sc, const RenderOptions& ro, Engines& model, const RenderResult& first,
                     size_t frames, RenderResult& scratch);

}  // namespace shd::cli
