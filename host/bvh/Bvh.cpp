#include "bvh/Bvh.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace snell {
namespace {

constexpr int kBins = 16;
// Relative cost of one node visit against one primitive test (SAH constants).
constexpr double kTraversalCost = 1.0;
constexpr double kIntersectionCost = 1.5;

struct BuildTask {
    std::uint32_t node;
    std::uint32_t begin;
    std::uint32_t end;
    int depth;
};

struct Split {
    double cost = 1e308;  // the surface area heuristic's, before the constants
    int axis = -1, bin = 0;  // axis -1: no axis has centroids apart
};

// Best split over the binned centroids on every axis.
Split bestSplit(const std::vector<Aabb>& primitives, const std::vector<glm::dvec3>& centroid,
                const std::vector<std::uint32_t>& order, const BuildTask& task, const Aabb& centroidBounds) {
    Split best;
    for (int axis = 0; axis < 3; ++axis) {
        const double lo = centroidBounds.lower[axis], hi = centroidBounds.upper[axis];
        if (!(hi > lo)) continue;
        const double toBin = kBins / (hi - lo);
        std::array<Aabb, kBins> binBounds{};
        std::array<std::uint32_t, kBins> binCount{};
        for (std::uint32_t i = task.begin; i < task.end; ++i) {
            const std::uint32_t p = order[i];
            const int b = std::min(kBins - 1, static_cast<int>((centroid[p][axis] - lo) * toBin));
            binBounds[b].grow(primitives[p]);
            ++binCount[b];
        }
        std::array<double, kBins> rightArea{};
        std::array<std::uint32_t, kBins> rightCount{};
        Aabb acc;
        std::uint32_t accCount = 0;
        for (int b = kBins - 1; b > 0; --b) {
            acc.grow(binBounds[b]);
            accCount += binCount[b];
            rightArea[b] = acc.halfArea();
            rightCount[b] = accCount;
        }
        acc = Aabb{};
        accCount = 0;
        for (int b = 0; b < kBins - 1; ++b) {
            acc.grow(binBounds[b]);
            accCount += binCount[b];
            if (accCount == 0 || rightCount[b + 1] == 0) continue;
            const double cost = acc.halfArea() * accCount + rightArea[b + 1] * rightCount[b + 1];
            if (cost < best.cost) best = {cost, axis, b};
        }
    }
    return best;
}

}  // namespace

Bvh buildBvh(const std::vector<Aabb>& primitives, std::uint32_t maxLeafSize) {
    Bvh bvh;
    const auto n = static_cast<std::uint32_t>(primitives.size());
    bvh.order.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) bvh.order[i] = i;
    std::vector<glm::dvec3> centroid(n);
    for (std::uint32_t i = 0; i < n; ++i)
        centroid[i] = 0.5 * (primitives[i].lower + primitives[i].upper);

    bvh.nodes.reserve(n == 0 ? 1 : 2 * n);
    bvh.nodes.push_back({});
    std::vector<BuildTask> tasks{{0, 0, n, 1}};
    while (!tasks.empty()) {
        const BuildTask task = tasks.back();
        tasks.pop_back();
        bvh.depth = std::max(bvh.depth, task.depth);
        Aabb bounds, centroidBounds;
        for (std::uint32_t i = task.begin; i < task.end; ++i) {
            bounds.grow(primitives[bvh.order[i]]);
            centroidBounds.grow(centroid[bvh.order[i]]);
        }
        const std::uint32_t count = task.end - task.begin;
        auto makeLeaf = [&] {
            bvh.nodes[task.node] = {bounds, task.begin, count};
        };
        if (count <= 1) { makeLeaf(); continue; }

        const Split best = bestSplit(primitives, centroid, bvh.order, task, centroidBounds);
        const double bestCost = best.cost;
        int bestAxis = best.axis;
        const int bestBin = best.bin;
        const double parentArea = bounds.halfArea();
        const double leafCost = kIntersectionCost * count;
        const double splitCost =
            kTraversalCost + kIntersectionCost * (parentArea > 0 ? bestCost / parentArea : 0.0);
        if (bestAxis < 0 || (count <= maxLeafSize && leafCost <= splitCost)) {
            if (bestAxis < 0 && count > maxLeafSize) {
                // All centroids coincide: split in the middle of the list.
                bestAxis = -2;
            } else {
                makeLeaf();
                continue;
            }
        }
        std::uint32_t middle;
        if (bestAxis == -2) {
            middle = task.begin + count / 2;
        } else {
            const double lo = centroidBounds.lower[bestAxis], hi = centroidBounds.upper[bestAxis];
            const double toBin = kBins / (hi - lo);
            auto* first = bvh.order.data() + task.begin;
            auto* last = bvh.order.data() + task.end;
            auto* mid = std::partition(first, last, [&](std::uint32_t p) {
                return std::min(kBins - 1, static_cast<int>((centroid[p][bestAxis] - lo) * toBin)) <= bestBin;
            });
            middle = static_cast<std::uint32_t>(mid - bvh.order.data());
        }
        const auto left = static_cast<std::uint32_t>(bvh.nodes.size());
        bvh.nodes.push_back({});
        bvh.nodes.push_back({});
        bvh.nodes[task.node] = {bounds, left, 0};
        tasks.push_back({left, task.begin, middle, task.depth + 1});
        tasks.push_back({left + 1, middle, task.end, task.depth + 1});
    }
    return bvh;
}

}  // namespace snell

namespace snell {
Aabb sphereBounds(const Sphere& sphere) {
    Aabb b;
    glm::dvec3 half;
    if (sphere.isTrueSphere) {
        half = glm::dvec3(sphere.radius);
    } else {
        const glm::dmat3 a(sphere.worldFromObject);
        for (int i = 0; i < 3; ++i) half[i] = std::sqrt(a[0][i] * a[0][i] + a[1][i] * a[1][i] + a[2][i] * a[2][i]);
    }
    b.lower = sphere.centre - half;
    b.upper = sphere.centre + half;
    return b;
}
}  // namespace snell
