// Bounding-volume hierarchy over the scene's spheres, built on the host with
// binned SAH (Wald, "On fast Construction of SAH-based Bounding Volume
// Hierarchies", 2007) in O(n log n). Traversed by the CPU reference in double
// and, converted to float with outward rounding, by the compute shader.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace snell {

struct Aabb {
    glm::dvec3 lower{1e308};
    glm::dvec3 upper{-1e308};
    void grow(const Aabb& b) {
        lower = glm::min(lower, b.lower);
        upper = glm::max(upper, b.upper);
    }
    void grow(const glm::dvec3& p) {
        lower = glm::min(lower, p);
        upper = glm::max(upper, p);
    }
    double halfArea() const {
        const glm::dvec3 e = glm::max(upper - lower, glm::dvec3(0.0));
        return e.x * e.y + e.y * e.z + e.z * e.x;
    }
};

struct BvhNode {
    Aabb bounds;
    // Inner node (count == 0): children at first and first + 1.
    // Leaf: primitives order[first .. first + count).
    std::uint32_t first = 0;
    std::uint32_t count = 0;
};

struct Bvh {
    std::vector<BvhNode> nodes;        // nodes[0] is the root
    std::vector<std::uint32_t> order;  // primitive indices in leaf order
    int depth = 0;                     // longest root-to-leaf path (nodes)
};

// Build over the given primitive bounds; maxLeafSize bounds a leaf's size.
Bvh buildBvh(const std::vector<Aabb>& primitives, std::uint32_t maxLeafSize = 4);

}  // namespace snell

#include "scene/Scene.h"

namespace snell {
// Exact axis-aligned bounds of a sphere or ellipsoid: for the unit sphere seen
// through x -> A x + t, the half-extent along axis i is the norm of A's row i.
Aabb sphereBounds(const Sphere& sphere);
}  // namespace snell
