// The shading methods' table: one row per Method (render/methods.cpp) with its name, the traits
// the shared pipeline asks about, and the unit that draws it (render/methods/*.cpp, where each
// method is described). parseMethod, toString(Method) and allMethods read the same table.
//
// A new method: its Method value (render.h), its unit (a MethodUnit in render/methods/, listed
// in model/CMakeLists.txt) and its row.
#pragma once

#include <cstddef>
#include <memory>

#include "render/render.h"

namespace shd {

class Frame;
class MethodUnit;

// What the span unit interpolates in attributes 0..2 (render.h): the colour (LSBs, 12 fraction
// bits) or the normal (camera space, 28 fraction bits).
enum class Attributes { Colour, Normal };

// Where a two-thread frame hands a screen triangle from its front end to its back end.
enum class TwoThreads {
  No,          // one thread only
  AfterSetup,  // set up by the front end; walked, shaded and written by the back end
  AfterWalk,   // set up and walked by the front end (the back end's shading is the longer half)
};

struct MethodTraits {
  Method method;
  const char* name;
  Attributes attributes;
  // Shades the Gouraud vertex colours (each vertex once, and only vertices of triangles that
  // survive back-face culling).
  bool vertex_colours;
  // Lights each polygon by its face normal (flat: Frame::faceColour), and so reads no vertex
  // normal (PVertex::n): the transform leaves them 0 (transformVertexRange). Where no specular
  // unit counts the lighting, the drawer lights the polygons of an object's triangles that are
  // not culled early in a pass of their own before it draws them (lightFaces, render.cpp): their
  // square roots, divisions and pow overlap there, where one polygon's waited out its own
  // latency before its setup.
  bool face_colours;
  // Evaluates the lobe per pixel: device lobes make specular-unit requests per pixel, batched
  // per triangle when the unit is not the model (Frame::batchesRequests).
  bool pixel_lobe;
  // Exact: the lobes themselves (a device lobe's Blinn lobe, no specular unit) and the
  // framebuffer's lsb and spec_lsb.
  bool exact;
  // Whether and where a frame may split between two threads (RenderOptions::threads,
  // render.cpp): the lobe is evaluated on one side alone, the front (vertex or polygon colours)
  // or the back (per pixel), so the two threads share no specular unit and no object state; and
  // the unit's draw() reads the setup alone, not SpanTriangle::v (the back end passes none).
  TwoThreads two_threads;
  // The unit reads of a screen triangle its walk and its plane's gradients alone, so a small one
  // may come as its rows' spans instead of a setup (SpanTriangle::rows, raster/row_spans.h).
  // (modified-gouraud and adaptive draw their parts with the gouraud and phong units, whose
  // rows apply.)
  bool row_spans;
  std::unique_ptr<MethodUnit> (*make)(Frame&);
};

// The table, one row per Method in its order (render/methods.cpp).
extern const MethodTraits kMethodTable[];
inline const MethodTraits& traits(Method m) { return kMethodTable[static_cast<size_t>(m)]; }

}  // namespace shd
