// A scene in POV-Ray 3.7's language, for the benchmark's peer: the same
// camera, spheres (through their full matrices), lights and background,
// Phong terms, mirror reflection and refraction, with adc_bailout 0.
// Where the two models agree (opaque spheres, grey ks) its image is SPEC's to
// 1/255 when POV-Ray writes linear values (File_Gamma=1.0); they differ in
// that POV-Ray's shadows pass through transparent spheres, its transparency
// dims the surface's own light, its air has index 1.0, and its Phong
// highlight has one strength (the mean of ks).
#pragma once

#include <string>

#include "scene/Scene.h"

namespace snell {

// POV-Ray counts the camera ray as a level: `max_trace_level N` traces the
// tree that snell's `--depth N-1` traces.
inline int povTraceLevel(int snellDepth) { return snellDepth + 1; }

// The scene traced to snell's `depth` (as max_trace_level povTraceLevel(depth)).
std::string toPovRay(const Scene& scene, int depth);

// Whether POV-Ray's image may be held to snell's: every sphere opaque (kt 0).
bool povModelAgrees(const Scene& scene);

}  // namespace snell
