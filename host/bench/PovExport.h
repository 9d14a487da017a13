// A scene in POV-Ray 3.7's language, for the benchmark's peer:
// the same camera, spheres (through their full matrices), lights and
// background, Phong terms, mirror reflection and refraction, traced to
// `maxTraceLevel` with adc_bailout 0. POV-Ray's shading model differs from
// SPEC's, so its images are compared by time, not colour.
#pragma once

#include <string>

#include "scene/Scene.h"

namespace snell {

std::string toPovRay(const Scene& scene, int maxTraceLevel);

}  // namespace snell
