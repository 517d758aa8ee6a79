// The span-unit descriptors of a scene, recorded through the render pipeline's public SpanEngine
// interface (model/render/render.h): render() sets up every visible screen triangle and hands its
// descriptor to SpanEngine::run(); RecordingSpanEngine keeps a copy and runs the model, so the
// frame renders as usual. Method gouraud (the span unit's own use), each material's BRDF.
#pragma once

#include <string>
#include <vector>

#include "raster/span_unit.h"

namespace shd {

struct SceneDescriptors {
  std::vector<SpanDesc> descs;   // in the order render() drew them
  uint64_t scene_triangles = 0;  // input triangles of every object
  uint64_t culled = 0;
  uint64_t frame_fragments = 0;  // fragments of the frame (the model's run)
  uint64_t frame_cycles = 0;     // span-unit cycles of the frame, consumer always ready
};

// scene: any loadScene() spec ("builtin:sphere", a JSON scene, a mesh file). p: the span unit
// the descriptors are made for (its lane layout decides the 4-way split of sierpinski).
// SceneError / std::invalid_argument for a scene the pipeline cannot take.
SceneDescriptors recordSceneDescriptors(const std::string& scene, const SpanParams& p);

}  // namespace shd
