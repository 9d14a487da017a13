// The CPU reference renderer: SPEC §3–§6 in double precision, on all cores.
// It is the project's oracle (the "exact image" every error is measured
// against) and the `--cpu` back end. Its traceTree() is the twin of the
// compute shader's main (shaders/trace.comp): the same steps, by the same
// names (cameraRay, admitRay, findHit, localTerm, followChildren, children),
// in the same order; docs/design.md maps each to its shader function.
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "bvh/Bvh.h"
#include "render/Reach.h"
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
        double estimatedError = std::numeric_limits<double>::infinity();  // the last one made (+inf: none)
        int deepest = 0;            // the deepest ray traced
        // A decision of its trees was within its rounding margin (Margins.h):
        // both outcomes are covered, so `bound` holds on both sides of the
        // colour, and `widening` of it is that.
        bool undecided = false;
        double widening = 0.0;
        double gap = 0.0;  // its truncation bound before the clamp, largest channel (+inf: none)
        // As a renderer reports it, for pixel (x, y).
        PixelTruncation truncation(int x, int y) const;
    };
    // sampleMask: only the samples whose bit is set (bit k: the request's
    // sample firstSample + k), their mean; 0: all of them.
    Pixel renderPixel(const RenderRequest& request, int x, int y, RayCounts& counts,
                      std::uint64_t sampleMask = 0) const;
    const RadianceBound& radiance() const { return radiance_; }

    // The closest hit of a ray (SPEC §4.1) and how sure it is (Margins.h).
    struct Closest {
        double t = kNoHit;
        std::uint32_t sphere = 0xffffffffu;
        double margin = 0.0;     // the exact hit lies within this of t
        bool undecided = false;  // the exact ray may hit another sphere first, or none
    };

private:
    struct Hit;
    struct PendingRay;
    struct Children;
    struct TreeTrace;
    static PendingRay cameraRay(const Camera& camera, int s, int x, int y, int k);
    void traceTree(const PendingRay& root, glm::dvec3& pixelSum, double saturation, double cutOff,
                   const TraceSettings& settings, RayCounts& counts, TreeTrace& tree) const;
    bool admitRay(PendingRay& r, const glm::dvec3& pixelSum, double saturation, double cutOff,
                  const TraceSettings& settings, RayCounts& counts, TreeTrace& tree) const;
    bool findHit(const PendingRay& r, Hit& hit) const;
    glm::dvec3 outwardNormal(const Sphere& sphere, const Ray& ray, double t, double& turning) const;
    // What of a local term may be off: the light of shadow rays whose answer
    // is undecided, and shading's rounding (Margins.h).
    struct Uncertain {
        glm::dvec3 light{0.0};   // may be off either way
        glm::dvec3 excess{0.0};  // of the term returned, what the exact term may lack (whiteEitherWay)
        bool undecided = false;
    };
    glm::dvec3 localTerm(const Hit& hit, const glm::dvec3& v, const TraceSettings& settings, RayCounts& counts,
                         Uncertain& uncertain) const;
    glm::dvec3 ambientTerm(const Hit& hit) const;
    glm::dvec3 shadeLight(const Light& light, const Hit& hit, const glm::dvec3& v, const TraceSettings& settings,
                          bool& castShadowRay, Uncertain& uncertain) const;
    void followChildren(const PendingRay& r, const Hit& hit, double cutOff, const TraceSettings& settings,
                        TreeTrace& tree, std::vector<PendingRay>& stack) const;
    Children children(const PendingRay& r, const Hit& hit, const TraceSettings& settings) const;
    Closest closestHit(const Ray& ray, std::uint32_t fromSphere, StartsOn start,
                       const margins::Uncertainty& off) const;
    // SPEC §4.3 visibility; `undecided`: the exact ray's answer may differ.
    bool occluded(const Ray& ray, double distance, std::uint32_t fromSphere, StartsOn start,
                  const margins::Uncertainty& off, bool& undecided) const;
    Crossing intersect(std::uint32_t sphere, const Ray& ray, std::uint32_t fromSphere, StartsOn start,
                       const margins::Uncertainty& off) const;
    template <class Reach, class Visit>
    void eachCandidate(const Ray& ray, Reach reach, Visit visit) const;


    // growthTraps for a render's eye, kept for the next render from there,
    // and whether the reach's inward bounds hold for it (inwardHolds).
    std::shared_ptr<const std::vector<bool>> trapsFor(const glm::dvec3& eye, bool& inwardHolds) const;

    const Scene& scene_;
    Bvh bvh_;
    bool useBvh_ = false;
    bool amplifying_ = false;
    RadianceBound radiance_;
    ReachBound reach_;  // the light a ray can still bring, by where it starts
    mutable std::mutex trapsMutex_;
    mutable std::shared_ptr<const std::vector<bool>> traps_;
    mutable glm::dvec3 trapsEye_{0.0};
    mutable bool inwardHolds_ = false;
};

}  // namespace snell
