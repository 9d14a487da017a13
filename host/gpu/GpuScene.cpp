#include "gpu/GpuScene.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>

#include "bvh/Bvh.h"
#include "render/Reach.h"
#include "render/Truncation.h"

namespace snell::gpu {
static_assert(snell::kMediaStackLimit == SNELL_MAX_MEDIA_LIMIT);

namespace {

vec4 toVec4(const snell::dvec3& v, double w) {
    return vec4(static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), static_cast<float>(w));
}

// v in float, each channel rounded up (+inf stays +inf): a bound stays one.
vec4 roundedUp(const snell::dvec3& v) {
    vec4 r(0.0f);
    for (int k = 0; k < 3; ++k) {
        r[k] = static_cast<float>(v[k]);
        if (double(r[k]) < v[k]) r[k] = std::nextafter(r[k], std::numeric_limits<float>::infinity());
    }
    return r;
}

// v and w as float pairs: hi gets the rounded values, lo what rounding lost.
void splitVec4(const snell::dvec3& v, double w, vec4& hi, vec4& lo) {
    for (int k = 0; k < 3; ++k) splitDouble(v[k], hi[k], lo[k]);
    splitDouble(w, hi.w, lo.w);
}

// Round a box outwards to float so it still contains the double box.
void outwardBox(const snell::Aabb& box, const snell::dvec3& eye, vec4& lower, vec4& upper) {
    for (int k = 0; k < 3; ++k) {
        const double lo = box.lower[k] - eye[k];
        const double hi = box.upper[k] - eye[k];
        float l = static_cast<float>(lo), h = static_cast<float>(hi);
        if (static_cast<double>(l) > lo) l = std::nextafter(l, -INFINITY);
        if (static_cast<double>(h) < hi) h = std::nextafter(h, INFINITY);
        lower[k] = l;
        upper[k] = h;
    }
    lower.w = upper.w = 0.0f;
}

// A sphere's box for a ray-box test that the device does in float (a ray
// query): rounded outwards, then padded by 2^-18 of its largest coordinate or
// extent, far more than the few units in the last place a float slab test
// can be off (Ize, "Robust BVH Ray Traversal", JCGT 2013), so a ray that
// meets the sphere is never culled. A larger box only costs a sphere test.
SphereBox paddedBox(const snell::Aabb& box, const snell::dvec3& origin) {
    vec4 lower, upper;
    outwardBox(box, origin, lower, upper);
    SphereBox out;
    for (int k = 0; k < 3; ++k) {
        const float scale = std::max({std::abs(lower[k]), std::abs(upper[k]), upper[k] - lower[k]});
        const float pad = scale * 0x1p-18f + std::numeric_limits<float>::min();
        out.lower[k] = lower[k] - pad;
        out.upper[k] = upper[k] + pad;
    }
    return out;
}

}  // namespace

void splitDouble(double v, float& hi, float& lo) {
    hi = static_cast<float>(v);
    lo = std::isfinite(hi) ? static_cast<float>(v - static_cast<double>(hi)) : 0.0f;
}

double primaryStartDistance(const snell::Scene& scene, const snell::dvec3& eye) {
    // The nearest any sphere's bounding sphere comes to the eye, less a margin
    // for the float rounding of the start point along the ray (≈ 2⁻²⁴ D) and a
    // sliver of the nearest sphere's size.
    double nearest = std::numeric_limits<double>::infinity();
    double nearestRadius = 0.0;
    for (const snell::Sphere& s : scene.spheres) {
        const double d = glm::length(s.centre - eye) - s.radius;
        if (d < nearest) {
            nearest = d;
            nearestRadius = s.radius;
        }
    }
    if (!(nearest > 0.0) || !std::isfinite(nearest)) return 0.0;
    const double margin = 16.0 * 0x1p-24 * nearest + 1e-3 * nearestRadius;
    return std::max(0.0, nearest - margin);
}

namespace {

// The binary BVH's nodes gathered under a node of up to SNELL_BVH_WIDTH
// children: starting from binary node n, the inner child of largest surface
// is replaced by its two children while there is room (Wald et al.,
// "Getting Rid of Packets", 2008, collapse a binary BVH this way). Fewer,
// wider steps: each step tests four boxes at once.
std::vector<std::uint32_t> wideChildren(const snell::Bvh& bvh, std::uint32_t n) {
    std::vector<std::uint32_t> children{n};
    while (children.size() < SNELL_BVH_WIDTH) {
        std::size_t widest = children.size();
        for (std::size_t k = 0; k < children.size(); ++k) {
            const snell::BvhNode& c = bvh.nodes[children[k]];
            if (c.count == 0 && (widest == children.size() ||
                                 c.bounds.halfArea() > bvh.nodes[children[widest]].bounds.halfArea()))
                widest = k;
        }
        if (widest == children.size()) break;
        const std::uint32_t first = bvh.nodes[children[widest]].first;
        children[widest] = first;
        children.insert(children.begin() + static_cast<std::ptrdiff_t>(widest) + 1, first + 1);
    }
    return children;
}

// Lays out the wide node over binary node n (and, depth first, those below
// it) from out.nodes' end; returns the depth of wide nodes from it.
int layOutWideNode(const snell::Bvh& bvh, std::uint32_t n, const snell::dvec3& eye, GpuScene& out) {
    const std::size_t index = out.nodes.size();
    out.nodes.emplace_back();
    const std::vector<std::uint32_t> children = wideChildren(bvh, n);
    std::uint32_t codes[SNELL_BVH_WIDTH];
    vec4 lower[SNELL_BVH_WIDTH], upper[SNELL_BVH_WIDTH];
    int depth = 1;
    for (std::size_t k = 0; k < SNELL_BVH_WIDTH; ++k) {
        lower[k] = upper[k] = vec4(0.0f);
        if (k >= children.size()) {
            codes[k] = SNELL_BVH_EMPTY;
            continue;
        }
        const snell::BvhNode& c = bvh.nodes[children[k]];
        outwardBox(c.bounds, eye, lower[k], upper[k]);
        if (c.count > 0) {
            codes[k] = SNELL_BVH_LEAF | (c.first * 4 + c.count - 1);
        } else {
            codes[k] = static_cast<std::uint32_t>(out.nodes.size());
            depth = std::max(depth, 1 + layOutWideNode(bvh, children[k], eye, out));
        }
    }
    BvhNode& node = out.nodes[index];
    for (int k = 0; k < SNELL_BVH_WIDTH; ++k) {
        node.lowerX[k] = lower[k].x, node.upperX[k] = upper[k].x;
        node.lowerY[k] = lower[k].y, node.upperY[k] = upper[k].y;
        node.lowerZ[k] = lower[k].z, node.upperZ[k] = upper[k].z;
        node.child[k] = std::bit_cast<float>(codes[k]);  // uint bits (shared_layout.h)
    }
    return depth;
}

// The BVH over the scene's spheres, laid out for the shader in out.nodes
// (nodes of four children, depth first); returns the spheres in leaf order.
std::vector<std::uint32_t> layOutBvh(const snell::Scene& scene, const snell::dvec3& eye, GpuScene& out) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<snell::Aabb> bounds;
    bounds.reserve(scene.spheres.size());
    for (const snell::Sphere& s : scene.spheres) bounds.push_back(snell::sphereBounds(s));
    const snell::Bvh bvh = snell::buildBvh(bounds, SNELL_BVH_MAX_LEAF);
    out.nodes.reserve(bvh.nodes.size() / 2 + 1);
    out.bvhDepth = layOutWideNode(bvh, 0, eye, out);
    out.bvhBuildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return bvh.order;
}

}  // namespace

GpuScene buildGpuScene(const snell::Scene& scene, const snell::Camera& camera, Precision precision, BvhMode bvh,
                       bool sphereBoxes) {
    GpuScene out;
    out.precision = precision;
    const bool wide = precision == Precision::Fp64;
    out.eye = camera.eye;
    // The GPU's coordinate origin: where the central primary ray starts.
    out.primaryStart = primaryStartDistance(scene, camera.eye);
    out.origin = camera.eye + out.primaryStart * camera.forward;
    const snell::dvec3 eye = out.origin;  // everything below is relative to it
    // objectFromOrigin = objectFromWorld · T(origin), in double.
    snell::dmat4 worldFromCamera(1.0);
    worldFromCamera[3] = glm::dvec4(eye, 1.0);

    std::vector<std::uint32_t> order(scene.spheres.size());
    for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    const bool useBvh = bvh == BvhMode::On ? scene.spheres.size() > 1
                        : bvh == BvhMode::Off ? false
                                              : scene.spheres.size() > kBvhThreshold;
    if (useBvh) order = layOutBvh(scene, eye, out);
    if (useBvh && sphereBoxes) {
        out.sphereBoxes.reserve(order.size());
        for (std::uint32_t index : order) out.sphereBoxes.push_back(paddedBox(snell::sphereBounds(scene.spheres[index]), eye));
    }

    out.spheres.reserve(scene.spheres.size());
    out.sphereMaterials.reserve(scene.spheres.size());
    if (wide) out.sphereLows.reserve(scene.spheres.size());
    for (std::uint32_t index : order) {
        const snell::Sphere& s = scene.spheres[index];
        Sphere g{}, low{};
        const snell::dvec3 centre = s.centre - eye;
        if (s.isTrueSphere) {
            // The anchor: the surface point nearest the origin, and its normal.
            const double distance = glm::length(centre);
            const snell::dvec3 n0 = distance > 0.0 ? -centre / distance : snell::dvec3(0.0, 0.0, 1.0);
            const snell::dvec3 anchor = centre + s.radius * n0;
            splitVec4(anchor, s.radius, g.anchorRadius, low.anchorRadius);
            splitVec4(n0, glm::length(anchor), g.normal, low.normal);
            out.sphereExtent = std::max(out.sphereExtent, distance + s.radius);
        } else {
            // An ellipsoid: its index as −1 − e in w (shared_layout.h), its map's rows.
            const double e = static_cast<double>(out.ellipsoids.size());
            splitVec4(centre, -1.0 - e, g.anchorRadius, low.anchorRadius);
            const snell::dmat4 objectFromOrigin = s.objectFromWorld * worldFromCamera;
            double matrixNorm = 0.0;
            for (int r = 0; r < 3; ++r)
                matrixNorm = std::max(matrixNorm, std::abs(objectFromOrigin[0][r]) + std::abs(objectFromOrigin[1][r]) +
                                                      std::abs(objectFromOrigin[2][r]));
            splitVec4(snell::dvec3(0.0), matrixNorm, g.normal, low.normal);
            Ellipsoid rows, rowLows;
            vec4* hi[3] = {&rows.row0, &rows.row1, &rows.row2};
            vec4* lo[3] = {&rowLows.row0, &rowLows.row1, &rowLows.row2};
            for (int r = 0; r < 3; ++r)
                splitVec4(snell::dvec3(objectFromOrigin[0][r], objectFromOrigin[1][r], objectFromOrigin[2][r]),
                          objectFromOrigin[3][r], *hi[r], *lo[r]);
            out.ellipsoids.push_back(rows);
            if (wide) out.ellipsoidLows.push_back(rowLows);
        }
        if (scene.materials[s.material].refracts()) ++out.refractiveSpheres;
        out.spheres.push_back(g);
        out.sphereMaterials.push_back(s.material);
        if (wide) out.sphereLows.push_back(low);
    }
    const std::vector<bool> traps = snell::growthTraps(scene, eye);
    for (std::size_t i = 0; i < scene.materials.size(); ++i) {
        const snell::Material& m = scene.materials[i];
        out.materials.push_back({toVec4(m.kd, m.phong), toVec4(m.ks, traps[i] ? 1.0 : 0.0), toVec4(m.kt, m.eta)});
        out.traps = out.traps || traps[i];
    }
    out.amplifying = scene.anyAmplifying();
    // Each sphere's reach, in the GPU's order, where some is below R: leaving
    // a sphere, or entering one that refracts (only an eye inside sends rays
    // into the others).
    const snell::RadianceBound radiance = snell::radianceBound(scene);
    const snell::ReachBound reach = snell::reachBound(scene, radiance);
    bool below = false;
    for (std::size_t i = 0; i < scene.spheres.size(); ++i) {
        const bool refracts = scene.materials[scene.spheres[i].material].refracts();
        for (int c = 0; c < 3; ++c)
            below = below || reach.outward[i][c] < radiance.radiance[c] ||
                    (refracts && reach.inward[i][c] < radiance.radiance[c]);
    }
    if (below) {
        out.reach.reserve(order.size());
        for (std::uint32_t index : order)
            out.reach.push_back({roundedUp(reach.outward[index]), roundedUp(reach.inward[index])});
        out.hollow = reach.hollow;
    }
    for (const snell::Light& l : scene.lights) {
        Light light{}, low{};
        splitVec4(l.position - eye, 1.0, light.position, low.position);
        light.colour = toVec4(l.colour, 0.0);
        out.lights.push_back(light);
        if (wide) out.lightLows.push_back(low);
    }
    return out;
}

FrameParams makeFrameParams(const snell::Scene& scene, const GpuScene& gpuScene, const snell::RenderRequest& request,
                            FrameParams* lowParts) {
    const snell::Camera& camera = request.camera;
    const snell::TraceSettings& trace = request.trace;
    const int supersample = std::max(1, request.supersample);
    FrameParams f{}, low{};
    // A camera other than the one the layout was built for (the preview's)
    // needs its own start distance.
    const double start = camera.eye == gpuScene.eye ? gpuScene.primaryStart : primaryStartDistance(scene, camera.eye);
    splitVec4(camera.eye - gpuScene.origin, start, f.primaryStart, low.primaryStart);
    splitVec4(camera.cornerDir, 0.0, f.cornerDir, low.cornerDir);
    splitVec4(camera.pixelRight, 0.0, f.pixelRight, low.pixelRight);
    splitVec4(camera.pixelDown, 0.0, f.pixelDown, low.pixelDown);
    // A few lights again in the frame (FrameParams.lights), with their low parts.
    if (gpuScene.lightsInFrame()) {
        std::copy(gpuScene.lights.begin(), gpuScene.lights.end(), f.lights);
        std::copy(gpuScene.lightLows.begin(), gpuScene.lightLows.end(), low.lights);
    }
    if (lowParts) *lowParts = low;
    f.background = toVec4(scene.background, 0.0);
    f.ambient = toVec4(scene.ambient, 0.0);
    // +inf stays +inf in float: the shader tests for it.
    const snell::RadianceBound radiance = snell::radianceBound(scene);
    f.radiance = toVec4(radiance.radiance, 0.0);
    f.localRadiance = toVec4(radiance.local, 0.0);
    f.minWeight = float(trace.minWeight);
    f.tolerance = float(trace.tolerance);
    f.amplifiedEstimate = float(snell::kAmplifiedEstimate);
    f.airEta = float(snell::kAirEta);
    // Rounded up: the shader's bound on a true sphere's offsets (FrameParams.sphereExtent).
    f.sphereExtent = std::nextafter(float(gpuScene.sphereExtent), std::numeric_limits<float>::infinity());
    f.imageWidth = static_cast<uint>(request.width);
    f.imageHeight = static_cast<uint>(request.height);
    f.supersample = static_cast<uint>(supersample);
    const int grid = supersample * supersample;
    f.firstSample = static_cast<uint>(std::clamp(request.firstSample, 0, grid - 1));
    f.sampleCount = static_cast<uint>(request.sampleCount > 0 ? std::min(request.sampleCount, grid - int(f.firstSample))
                                                              : grid - int(f.firstSample));
    f.maxDepth = static_cast<uint>(trace.maxDepth);
    f.treeBudget = static_cast<uint>(std::min<std::uint64_t>(trace.treeBudget, 0xffffffffu));
    f.estimate = trace.estimate ? 1u : 0u;
    f.sphereCount = static_cast<uint>(gpuScene.spheres.size());
    f.lightCount = static_cast<uint>(gpuScene.lights.size());
    f.bvhNodeCount = static_cast<uint>(gpuScene.nodes.size());
    f.reachInward = !gpuScene.reach.empty() && snell::inwardHolds(scene, gpuScene.hollow, camera.eye) ? 1u : 0u;
    return f;
}

std::size_t GpuScene::bytes() const {
    std::size_t total = 0;
    auto add = [&](const auto& v) { total += v.size() * sizeof(v[0]); };
    add(spheres), add(sphereMaterials), add(ellipsoids), add(materials), add(lights), add(nodes), add(sphereBoxes);
    add(sphereLows), add(ellipsoidLows), add(lightLows);
    return total;
}

}  // namespace snell::gpu
