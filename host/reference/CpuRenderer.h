// The CPU reference renderer: SPEC §3–§6 in double precision, on all cores.
// It is the project's oracle (the "exact image" every error is measured
// against) and the `--cpu` back end. Its trace() is the twin of the compute
// shader's trace() in shaders/trace.comp: same ray tree, same order.
#pragma once


#include "bvh/Bvh.h"
#include "render/RenderRequest.h"
#include "image/Image.h"
#include "reference/Intersect.h"
#include "scene/Scene.h"

namespace snell {

class CpuRenderer {
public:
    explicit CpuRenderer(const Scene& scene);
    Image render(const RenderRequest& request, RayCounts* counts = nullptr) const;

    // The colour of one pixel (exposed for tests).
    glm::dvec3 renderPixel(const RenderRequest& request, int x, int y, RayCounts& counts) const;

private:
    struct Hit;
    struct PendingRay;
    void trace(const PendingRay& primary, glm::dvec3& pixelSum, double saturation,
               const TraceSettings& settings, RayCounts& counts) const;
    bool closestHit(const Ray& ray, std::uint32_t fromSphere, StartsOn start, Hit& hit) const;
    bool occluded(const Ray& ray, double distance, std::uint32_t fromSphere, StartsOn start) const;
    double intersect(std::uint32_t sphere, const Ray& ray, std::uint32_t fromSphere, StartsOn start) const;

    const Scene& scene_;
    Bvh bvh_;
    bool useBvh_ = false;
    bool amplifying_ = false;
};

}  // namespace snell
