// The CPU reference renderer: SPEC §3–§6 in double precision, on all cores.
// It is the project's oracle (the "exact image" every error is measured
// against) and the `--cpu` back end. Its trace() is the twin of the compute
// shader's trace() in shaders/trace.comp: same ray tree, same order.
#pragma once

#include <memory>
#include <mutex>
#include <vector>

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

    // One pixel: its colour and what the cut-offs may have cost it.
    struct Pixel {
        glm::dvec3 colour{0.0};
        double bound = 0.0;         // on the clamped colour (render/Truncation.h)
        bool unbounded = false;     // light was dropped where it need not decay
        bool overBudget = false;    // a sample's tree reached TraceSettings::treeBudget
        bool overTolerance = false; // still above the tolerance at the floor cut-off
        bool estimated = false;     // unbounded, and stopped by its estimated error (render/Truncation.h)
        double estimatedError = 0.0;
        int deepest = 0;            // the deepest ray traced
    };
    Pixel renderPixel(const RenderRequest& request, int x, int y, RayCounts& counts) const;
    const RadianceBound& radiance() const { return radiance_; }

private:
    struct Hit;
    struct PendingRay;
    struct TreeTrace;
    void trace(const PendingRay& root, glm::dvec3& pixelSum, double saturation, double cutOff,
               const TraceSettings& settings, RayCounts& counts, TreeTrace& tree) const;
    void spawnChildren(const PendingRay& r, const Material& m, std::uint32_t hitSphere, const glm::dvec3& x,
                       const glm::dvec3& n, bool fromOutside, double cutOff, const TraceSettings& settings,
                       TreeTrace& tree, std::vector<PendingRay>& stack) const;
    glm::dvec3 outwardNormal(const Sphere& sphere, const Ray& ray, double t) const;
    glm::dvec3 localTerm(const Material& m, std::uint32_t hitSphere, const glm::dvec3& x, const glm::dvec3& n,
                         const glm::dvec3& v, bool fromOutside, const TraceSettings& settings,
                         RayCounts& counts) const;
    bool closestHit(const Ray& ray, std::uint32_t fromSphere, StartsOn start, Hit& hit) const;
    bool occluded(const Ray& ray, double distance, std::uint32_t fromSphere, StartsOn start) const;
    double intersect(std::uint32_t sphere, const Ray& ray, std::uint32_t fromSphere, StartsOn start) const;

    // growthTraps for a render's eye, kept for the next render from there.
    std::shared_ptr<const std::vector<bool>> trapsFor(const glm::dvec3& eye) const;

    const Scene& scene_;
    Bvh bvh_;
    bool useBvh_ = false;
    bool amplifying_ = false;
    RadianceBound radiance_;
    mutable std::mutex trapsMutex_;
    mutable std::shared_ptr<const std::vector<bool>> traps_;
    mutable glm::dvec3 trapsEye_{0.0};
};

}  // namespace snell
