// The CPU reference's searches (SPEC §4.1 closest hit, §4.3 visibility), by
// brute force or through the BVH, each answer with whether rounding could
// change it (Margins.h): the twin of shaders/physics/hit.glsl.
#include <algorithm>
#include <cmath>

#include "reference/CpuRenderer.h"

namespace snell {

using glm::dvec3;

namespace {

bool rayHitsBox(const Aabb& box, const dvec3& origin, const dvec3& inverseDir, double tMax) {
    // Slab test, the near and far planes chosen by the direction's signs.
    // Where the ray runs in a slab's plane (0 · ±inf) a distance is NaN,
    // which the comparisons below ignore: the slab does not narrow it.
    double t0 = 0.0, t1 = tMax;
    for (int k = 0; k < 3; ++k) {
        const bool negative = inverseDir[k] < 0.0;
        const double near = ((negative ? box.upper[k] : box.lower[k]) - origin[k]) * inverseDir[k];
        const double far = ((negative ? box.lower[k] : box.upper[k]) - origin[k]) * inverseDir[k];
        t0 = near > t0 ? near : t0;
        t1 = far < t1 ? far : t1;
    }
    return t0 <= t1;
}

// The nearest crossing offered so far, and the nearest any other sphere may be
// met by the exact ray: the closest hit is undecided when that rival may come
// first, or when the nearest crossing may be a miss.
struct Rivalry {
    CpuRenderer::Closest best;
    double rivalFrom = kNoHit;
    bool grazing = false;

    void offer(std::uint32_t sphere, const Crossing& c) {
        if (c.t < best.t) {
            rivalFrom = std::min(rivalFrom, best.t - best.margin);
            best.t = c.t;
            best.sphere = sphere;
            best.margin = c.margin;
            grazing = c.grazing;
        } else {
            rivalFrom = std::min(rivalFrom, c.rivalFrom);
        }
    }
    // Boxes entered beyond this hold no rival within the margins: twice the
    // best's margin stands for a rival's own (docs/decisions.md says where that
    // is not enough).
    double cull() const { return best.t + 2.0 * best.margin; }
    CpuRenderer::Closest finish() {
        best.undecided = grazing || (rivalFrom < kNoHit && rivalFrom <= best.t + best.margin);
        return best;
    }
};

}  // namespace

Crossing CpuRenderer::intersect(std::uint32_t index, const Ray& ray, std::uint32_t fromSphere, StartsOn start,
                                const margins::Uncertainty& off) const {
    const Sphere& s = scene_.spheres[index];
    const StartsOn mode = index == fromSphere ? start : StartsOn::Elsewhere;
    if (s.isTrueSphere) return crossSphere(s.centre, s.radius, ray, mode, off);
    const dvec3 o = dvec3(s.objectFromWorld * glm::dvec4(ray.origin, 1.0));
    const glm::dmat3 m(s.objectFromWorld);
    const dvec3 d = m * ray.direction;
    // Rounding of o: of the origin through the matrix, and of the product.
    double matrixNorm = 0.0;
    for (int row = 0; row < 3; ++row)
        matrixNorm = std::max(matrixNorm, std::abs(m[0][row]) + std::abs(m[1][row]) + std::abs(m[2][row]));
    const double originLength = glm::length(ray.origin);
    const double tolerance = kRounding * (glm::length(o) + 1.0 + matrixNorm * originLength);
    return crossUnitSphere(o, d, mode, tolerance, off, margins::acrossStretch(m, d), originLength);
}

// Offers `visit` every sphere the ray may meet before reach() (read at each
// box: a search narrows it): all of them, or those whose BVH boxes it enters.
// visit returns true to end the search.
template <class Reach, class Visit>
void CpuRenderer::eachCandidate(const Ray& ray, Reach reach, Visit visit) const {
    if (!useBvh_) {
        for (std::uint32_t i = 0; i < scene_.spheres.size(); ++i)
            if (visit(i)) return;
        return;
    }
    const dvec3 inverseDir = 1.0 / ray.direction;
    std::uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const BvhNode& node = bvh_.nodes[stack[--top]];
        if (!rayHitsBox(node.bounds, ray.origin, inverseDir, reach())) continue;
        if (node.count > 0) {
            for (std::uint32_t k = 0; k < node.count; ++k)
                if (visit(bvh_.order[node.first + k])) return;
        } else {
            stack[top++] = node.first;
            stack[top++] = node.first + 1;
        }
    }
}

CpuRenderer::Closest CpuRenderer::closestHit(const Ray& ray, std::uint32_t fromSphere, StartsOn start,
                                             const margins::Uncertainty& off) const {
    Rivalry search;
    eachCandidate(ray, [&] { return search.cull(); }, [&](std::uint32_t i) {
        search.offer(i, intersect(i, ray, fromSphere, start, off));
        return false;
    });
    return search.finish();
}

bool CpuRenderer::occluded(const Ray& ray, double distance, std::uint32_t fromSphere, StartsOn start,
                           const margins::Uncertainty& off, bool& undecided) const {
    // SPEC §4.3: blocked if a surface crosses the open segment (0, distance).
    // A crossing surely within it ends the search; one within its margin of
    // either end, or a near miss before the light, leaves the answer
    // undecided, and the search goes on for a sure one.
    undecided = false;
    bool blocked = false, surelyBlocked = false;
    auto surely = [&](const Crossing& c) {
        if (c.t < distance) {
            blocked = true;
            if (!c.grazing && c.t + c.margin < distance) return surelyBlocked = true;
            undecided = true;
        } else if (c.rivalFrom < distance) {
            undecided = true;
        }
        return false;
    };
    // A ray that starts on a sphere headed into it (shading a hit from inside)
    // crosses that sphere at its chord unless the light is nearer: that one
    // test first spares the search its answer.
    if (!(start == StartsOn::Entering && surely(intersect(fromSphere, ray, fromSphere, start, off))))
        eachCandidate(ray, [&] { return distance; },
                      [&](std::uint32_t i) { return surely(intersect(i, ray, fromSphere, start, off)); });
    if (surelyBlocked) undecided = false;
    return blocked;
}

}  // namespace snell
