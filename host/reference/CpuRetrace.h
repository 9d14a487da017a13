// The pixels whose decisions the GPU's float arithmetic left undecided
// (render/Margins.h), traced again by the CPU reference in double, where they
// are decided or, where not even double decides them, bounded both ways.
#pragma once

#include <functional>
#include <vector>

#include "render/RenderRequest.h"
#include "scene/Scene.h"

namespace snell {

// A RenderRequest::retrace for renders of `scene` with `request`'s camera and
// trace settings. The reference (its BVH) is built at the first pixel handed
// to it; pixels are traced on all cores.
std::function<void(std::vector<RetracedPixel>&)> cpuRetrace(const Scene& scene, const RenderRequest& request);

}  // namespace snell
