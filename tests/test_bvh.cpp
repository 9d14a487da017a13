// The BVH (bvh/Bvh.h) on its own: its structure (every sphere in exactly one
// leaf, every node's box around its children's, leaves no larger than asked,
// the depth it states) and its use (the closest hit found through it is the
// closest hit of all the spheres, on random rays), for random scenes and the
// degenerate ones: one sphere, coincident spheres, spheres in a plane.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "bvh/Bvh.h"
#include "reference/Intersect.h"
#include "scene/Scene.h"

namespace {

using glm::dvec3;

snell::Sphere trueSphere(dvec3 centre, double radius) {
    snell::Sphere s;
    s.isTrueSphere = true;
    s.centre = centre;
    s.radius = radius;
    return s;
}

std::vector<snell::Sphere> randomSpheres(int n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> position(-10.0, 10.0), radius(0.05, 1.5);
    std::vector<snell::Sphere> spheres;
    for (int i = 0; i < n; ++i) spheres.push_back(trueSphere({position(rng), position(rng), position(rng)}, radius(rng)));
    return spheres;
}

std::vector<snell::Aabb> boundsOf(const std::vector<snell::Sphere>& spheres) {
    std::vector<snell::Aabb> bounds;
    for (const snell::Sphere& s : spheres) bounds.push_back(snell::sphereBounds(s));
    return bounds;
}

bool contains(const snell::Aabb& outer, const snell::Aabb& inner) {
    for (int k = 0; k < 3; ++k)
        if (inner.lower[k] < outer.lower[k] || inner.upper[k] > outer.upper[k]) return false;
    return true;
}

// Walks the tree from the root: each primitive's leaf count (every one must be
// reached exactly once), every box around what lies below it, leaf sizes and
// the longest path.
void expectWellFormed(const snell::Bvh& bvh, const std::vector<snell::Aabb>& primitives, std::uint32_t maxLeafSize) {
    ASSERT_FALSE(bvh.nodes.empty());
    ASSERT_EQ(bvh.order.size(), primitives.size());
    std::vector<int> reached(primitives.size(), 0);
    struct Visit {
        std::uint32_t node;
        int depth;
    };
    std::vector<Visit> stack{{0, 1}};
    std::vector<int> visited(bvh.nodes.size(), 0);
    int deepest = 0;
    while (!stack.empty()) {
        const Visit v = stack.back();
        stack.pop_back();
        ASSERT_LT(v.node, bvh.nodes.size());
        ASSERT_EQ(visited[v.node]++, 0) << "node " << v.node << " reached twice";
        deepest = std::max(deepest, v.depth);
        const snell::BvhNode& node = bvh.nodes[v.node];
        if (node.count > 0) {
            EXPECT_LE(node.count, std::max<std::uint32_t>(maxLeafSize, 1)) << "leaf " << v.node;
            ASSERT_LE(std::size_t(node.first) + node.count, bvh.order.size());
            for (std::uint32_t k = 0; k < node.count; ++k) {
                const std::uint32_t p = bvh.order[node.first + k];
                ASSERT_LT(p, primitives.size());
                ++reached[p];
                EXPECT_TRUE(contains(node.bounds, primitives[p])) << "leaf " << v.node << " misses sphere " << p;
            }
            continue;
        }
        ASSERT_LT(std::size_t(node.first) + 1, bvh.nodes.size());
        for (std::uint32_t child : {node.first, node.first + 1}) {
            EXPECT_TRUE(contains(node.bounds, bvh.nodes[child].bounds)) << "node " << v.node << ", child " << child;
            stack.push_back({child, v.depth + 1});
        }
    }
    for (std::size_t p = 0; p < reached.size(); ++p) EXPECT_EQ(reached[p], 1) << "sphere " << p;
    EXPECT_EQ(deepest, bvh.depth);
}

// The ray's slab test against a box (Kay and Kajiya), for t in [0, tMax].
bool hitsBox(const snell::Aabb& box, const snell::Ray& ray, double tMax) {
    double t0 = 0.0, t1 = tMax;
    for (int k = 0; k < 3; ++k) {
        const double inverse = 1.0 / ray.direction[k];
        double a = (box.lower[k] - ray.origin[k]) * inverse, b = (box.upper[k] - ray.origin[k]) * inverse;
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
        if (t0 > t1) return false;
    }
    return true;
}

struct Closest {
    double t = snell::kNoHit;
    std::uint32_t sphere = ~0u;
};

Closest bruteForce(const std::vector<snell::Sphere>& spheres, const snell::Ray& ray) {
    Closest c;
    for (std::uint32_t i = 0; i < spheres.size(); ++i) {
        const double t = snell::intersectSphere(spheres[i].centre, spheres[i].radius, ray, snell::StartsOn::Elsewhere);
        if (t < c.t) c = {t, i};
    }
    return c;
}

// Through the tree, skipping every box the ray misses or meets beyond the
// closest hit so far; ties go to the lower index, as in bruteForce.
Closest throughBvh(const snell::Bvh& bvh, const std::vector<snell::Sphere>& spheres, const snell::Ray& ray) {
    Closest c;
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
        const snell::BvhNode& node = bvh.nodes[stack.back()];
        stack.pop_back();
        if (!hitsBox(node.bounds, ray, c.t == snell::kNoHit ? 1e300 : c.t)) continue;
        if (node.count == 0) {
            stack.push_back(node.first);
            stack.push_back(node.first + 1);
            continue;
        }
        for (std::uint32_t k = 0; k < node.count; ++k) {
            const std::uint32_t i = bvh.order[node.first + k];
            const double t =
                snell::intersectSphere(spheres[i].centre, spheres[i].radius, ray, snell::StartsOn::Elsewhere);
            if (t < c.t || (t == c.t && t != snell::kNoHit && i < c.sphere)) c = {t, i};
        }
    }
    return c;
}

// Random rays from a box around the scene towards points near random spheres
// (within 1.5 radii of the centre), so most of them hit something.
void expectClosestHitsAgree(const std::vector<snell::Sphere>& spheres, const snell::Bvh& bvh, int rays,
                            std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> from(-15.0, 15.0), near(-1.5, 1.5);
    std::uniform_int_distribution<std::size_t> pick(0, spheres.size() - 1);
    int hits = 0;
    for (int i = 0; i < rays; ++i) {
        const dvec3 origin(from(rng), from(rng), from(rng));
        const snell::Sphere& s = spheres[pick(rng)];
        const dvec3 target = s.centre + s.radius * dvec3(near(rng), near(rng), near(rng));
        const snell::Ray ray{origin, glm::normalize(target - origin)};
        const Closest expected = bruteForce(spheres, ray);
        const Closest found = throughBvh(bvh, spheres, ray);
        ASSERT_EQ(found.t, expected.t) << "ray " << i;
        ASSERT_EQ(found.sphere, expected.sphere) << "ray " << i;
        hits += expected.t != snell::kNoHit;
    }
    EXPECT_GT(hits, rays / 4) << "too few rays hit anything to test";
}

TEST(Bvh, EverySphereInOneLeafAndEveryBoxAroundItsChildren) {
    for (int n : {2, 3, 5, 17, 100, 1000}) {
        SCOPED_TRACE(n);
        const std::vector<snell::Aabb> bounds = boundsOf(randomSpheres(n, 7u + n));
        for (std::uint32_t leaf : {1u, 4u, 8u}) expectWellFormed(snell::buildBvh(bounds, leaf), bounds, leaf);
    }
}

TEST(Bvh, ClosestHitEqualsBruteForceOnRandomRays) {
    for (int n : {2, 10, 300}) {
        SCOPED_TRACE(n);
        const std::vector<snell::Sphere> spheres = randomSpheres(n, 100u + n);
        expectClosestHitsAgree(spheres, snell::buildBvh(boundsOf(spheres)), 2000, 5u + n);
    }
}

TEST(Bvh, OneSphereIsOneLeaf) {
    const std::vector<snell::Sphere> spheres{trueSphere({0, 0, -3}, 1.0)};
    const snell::Bvh bvh = snell::buildBvh(boundsOf(spheres));
    ASSERT_EQ(bvh.nodes.size(), 1u);
    EXPECT_EQ(bvh.nodes[0].count, 1u);
    EXPECT_EQ(bvh.depth, 1);
    expectWellFormed(bvh, boundsOf(spheres), 4);
    expectClosestHitsAgree(spheres, bvh, 500, 1);
}

// All centroids coincide: no split plane separates them, and the builder
// halves the list instead; every sphere must still be reached, and every ray
// that hits one hits the first (the same surface).
TEST(Bvh, CoincidentSpheresAreAllReached) {
    for (int n : {2, 5, 64}) {
        SCOPED_TRACE(n);
        const std::vector<snell::Sphere> spheres(n, trueSphere({1, 2, -3}, 0.5));
        const snell::Bvh bvh = snell::buildBvh(boundsOf(spheres));
        expectWellFormed(bvh, boundsOf(spheres), 4);
        expectClosestHitsAgree(spheres, bvh, 500, 2u + n);
    }
}

// Concentric spheres of different radii share a centroid too, and the ray
// must find the outermost one.
TEST(Bvh, ConcentricSpheresGiveTheOutermost) {
    std::vector<snell::Sphere> spheres;
    for (int i = 1; i <= 12; ++i) spheres.push_back(trueSphere({0, 0, 0}, 0.5 * i));
    const snell::Bvh bvh = snell::buildBvh(boundsOf(spheres));
    expectWellFormed(bvh, boundsOf(spheres), 4);
    expectClosestHitsAgree(spheres, bvh, 500, 3);
}

// Flat in one axis (the box of the centroids has no extent there) and spheres
// of very different sizes side by side.
TEST(Bvh, PlanarAndMixedSizeScenes) {
    std::vector<snell::Sphere> plane;
    for (int x = 0; x < 20; ++x)
        for (int y = 0; y < 20; ++y) plane.push_back(trueSphere({x - 10.0, y - 10.0, -5.0}, 0.4));
    expectWellFormed(snell::buildBvh(boundsOf(plane)), boundsOf(plane), 4);
    expectClosestHitsAgree(plane, snell::buildBvh(boundsOf(plane)), 2000, 4);

    std::vector<snell::Sphere> mixed = randomSpheres(50, 9);
    mixed.push_back(trueSphere({0, 0, -100}, 95.0));  // a huge floor behind the rest
    mixed.push_back(trueSphere({0.5, 0.5, 0.5}, 1e-4));
    expectWellFormed(snell::buildBvh(boundsOf(mixed)), boundsOf(mixed), 4);
    expectClosestHitsAgree(mixed, snell::buildBvh(boundsOf(mixed)), 2000, 5);
}

// An ellipsoid's box (sphereBounds) holds every point of its surface and
// touches it on each side: the norm of each row of its linear map.
TEST(Bvh, EllipsoidBoundsAreTight) {
    snell::Sphere e;
    const glm::dmat4 rotate = glm::dmat4(glm::dmat3(0.36, 0.48, -0.8, -0.8, 0.6, 0.0, 0.48, 0.64, 0.6));
    e.worldFromObject = glm::dmat4(1.0);
    e.worldFromObject[3] = glm::dvec4(1, -2, 3, 1);
    e.worldFromObject = e.worldFromObject * rotate * glm::dmat4(glm::dmat3(2.0, 0, 0, 0, 0.5, 0, 0, 0, 1.0));
    e.centre = dvec3(1, -2, 3);
    const snell::Aabb box = snell::sphereBounds(e);
    dvec3 lowest(1e300), highest(-1e300);
    std::mt19937 rng(11);
    std::normal_distribution<double> gauss;
    for (int i = 0; i < 20000; ++i) {
        const dvec3 onUnit = glm::normalize(dvec3(gauss(rng), gauss(rng), gauss(rng)));
        const dvec3 p(e.worldFromObject * glm::dvec4(onUnit, 1.0));
        for (int k = 0; k < 3; ++k) {
            EXPECT_GE(p[k], box.lower[k] - 1e-12);
            EXPECT_LE(p[k], box.upper[k] + 1e-12);
        }
        lowest = glm::min(lowest, p);
        highest = glm::max(highest, p);
    }
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(lowest[k], box.lower[k], 0.02) << k;
        EXPECT_NEAR(highest[k], box.upper[k], 0.02) << k;
    }
}

}  // namespace
