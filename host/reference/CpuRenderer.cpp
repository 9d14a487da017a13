#include "reference/CpuRenderer.h"

#include <algorithm>
#include <cmath>
#include <array>
#include <limits>
#include <optional>
#include <thread>
#include <vector>

namespace snell {

using glm::dvec3;

namespace {

constexpr std::uint32_t kNone = 0xffffffffu;
constexpr int kMaxMedia = 128;
constexpr std::size_t kBvhThreshold = 8;  // below this, a linear loop is as fast

// SPEC §4 medium stack: the refractive spheres a ray is inside, innermost last.
struct MediumStack {
    int size = 0;
    std::array<std::uint32_t, kMaxMedia> spheres{};

    void push(std::uint32_t s) {
        if (size == kMaxMedia) {  // deeper nesting than any real scene: forget the outermost
            std::copy(spheres.begin() + 1, spheres.end(), spheres.begin());
            --size;
        }
        spheres[size++] = s;
    }
    // Remove s wherever it is (SPEC: "or does nothing if it is not there").
    void remove(std::uint32_t s) {
        for (int i = size - 1; i >= 0; --i) {
            if (spheres[i] == s) {
                std::copy(spheres.begin() + i + 1, spheres.begin() + size, spheres.begin() + i);
                --size;
                return;
            }
        }
    }
};

double maxComponent(const dvec3& v) { return std::max({v.x, v.y, v.z}); }

// sum += weight ⊙ colour, where a weight grown to +inf (an amplifying tree,
// SPEC §4) times a colour of 0 adds nothing rather than NaN.
dvec3 weighted(const dvec3& weight, const dvec3& colour) {
    dvec3 r(0.0);
    for (int k = 0; k < 3; ++k)
        if (colour[k] != 0.0 && weight[k] != 0.0) r[k] = weight[k] * colour[k];
    return r;
}
void addWeighted(dvec3& sum, const dvec3& weight, const dvec3& colour) { sum += weighted(weight, colour); }

// The largest weight a ray carries (as the shader, whose float would overflow):
// a capped weight is at most the true one, so sums stay lower bounds.
constexpr double kMaxWeight = 1e30;
dvec3 childWeight(const dvec3& weight, const dvec3& gain) { return glm::min(weighted(weight, gain), dvec3(kMaxWeight)); }

// The gain of a hit's children together: ks reflected, kt transmitted.
dvec3 childrenGain(const Material& m, const TraceSettings& settings) {
    const dvec3 reflectedGain = settings.reflection ? m.ks : dvec3(0.0);
    const dvec3 transmittedGain = settings.refraction && m.refracts() ? m.kt : dvec3(0.0);
    return reflectedGain + transmittedGain;
}

// Whether a ray of weight w is traced under the cut-off.
bool worthTracing(const dvec3& w, double cutOff) {
    const double m = maxComponent(w);
    return m > 0.0 && m >= cutOff;
}

// A ray refracted at a surface of `sphere` (material m), entering it or
// leaving: the refractive index of the medium it leaves over that of the one
// it enters (SPEC §4.5), and `media` becomes the refracted ray's medium stack.
double crossSurface(const Scene& scene, bool entering, const Material& m, std::uint32_t sphere, MediumStack& media) {
    auto innermostEta = [&] {
        return media.size > 0 ? scene.materials[scene.spheres[media.spheres[media.size - 1]].material].eta : kAirEta;
    };
    if (entering) {
        const double etaI = innermostEta();
        media.push(sphere);
        return etaI / m.eta;
    }
    media.remove(sphere);
    return m.eta / innermostEta();
}

bool rayHitsBox(const Aabb& box, const dvec3& origin, const dvec3& inverseDir, double tMax) {
    // Slab test; inverseDir components may be ±inf, which the min/max handle.
    double t0 = 0.0, t1 = tMax;
    for (int k = 0; k < 3; ++k) {
        double a = (box.lower[k] - origin[k]) * inverseDir[k];
        double b = (box.upper[k] - origin[k]) * inverseDir[k];
        if (std::isnan(a) || std::isnan(b)) continue;  // origin on a slab plane, parallel ray
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
        if (t0 > t1) return false;
    }
    return true;
}

}  // namespace

// Where a ray met its closest surface, and what shading needs there.
struct CpuRenderer::Hit {
    double t = kNoHit;
    std::uint32_t sphere = kNone;
    const Material* material = nullptr;
    dvec3 point{0.0};
    dvec3 normal{0.0};         // the shading normal N (against the ray)
    bool fromOutside = false;  // the ray arrived from outside the sphere
};

struct CpuRenderer::PendingRay {
    Ray ray;
    dvec3 weight{1.0};
    int depth = 0;
    std::uint32_t fromSphere = kNone;  // the sphere whose surface the ray starts on
    bool inward = false;               // it starts into that sphere
    bool refracted = false;
    MediumStack media;
};

// One hit's children: the reflected ray, and the refracted one unless total
// internal reflection (or no refraction) leaves none.
struct CpuRenderer::Children {
    PendingRay reflected;
    std::optional<PendingRay> refracted;
};

// What a pixel's trees did not trace so far (render/Truncation.h): the weight
// lost for good (depth limit, tree budget) and the rays left under the cut-off
// (`frontier`, which a lower cut-off continues from); how many rays they traced
// and how deep they went.
struct CpuRenderer::TreeTrace {
    dvec3 lost{0.0};
    dvec3 deferred{0.0};          // the weight of the rays in `frontier`
    double heaviestDeferred = 0.0;
    std::vector<PendingRay> frontier;
    std::uint64_t rays = 0;
    std::uint64_t budget = 0;     // the most rays they may trace; 0: no limit
    int deepest = 0;
    bool overBudget = false;
    bool amplified = false;       // a hit met a trap (growthTraps) with light of a gain > 1
    const std::vector<bool>* traps = nullptr;  // per material (growthTraps)
    bool anyTrap = false;

    // A ray under the cut-off: the next, lower cut-off starts from it (under
    // the floor no cut-off will, and it is lost; but in a scene with traps a
    // pixel may go below the floor, renderPixel).
    void defer(PendingRay&& r, const TraceSettings& settings) {
        const double m = maxComponent(r.weight);
        if (!(m > 0.0)) return;
        const bool mayGoBelowFloor = anyTrap && settings.treeBudget != 0;
        if (!(settings.tolerance > 0.0) || (m < settings.minWeight && !mayGoBelowFloor)) {
            lost += r.weight;
            return;
        }
        deferred += r.weight;
        heaviestDeferred = std::max(heaviestDeferred, m);
        frontier.push_back(std::move(r));
    }
};

CpuRenderer::CpuRenderer(const Scene& scene) : scene_(scene) {
    amplifying_ = scene.anyAmplifying();
    radiance_ = radianceBound(scene);
    useBvh_ = scene.spheres.size() > kBvhThreshold;
    if (useBvh_) {
        std::vector<Aabb> bounds;
        bounds.reserve(scene.spheres.size());
        for (const Sphere& s : scene.spheres) bounds.push_back(sphereBounds(s));
        bvh_ = buildBvh(bounds);
    }
}

std::shared_ptr<const std::vector<bool>> CpuRenderer::trapsFor(const dvec3& eye) const {
    const std::lock_guard<std::mutex> lock(trapsMutex_);
    if (!traps_ || trapsEye_ != eye) {
        traps_ = std::make_shared<const std::vector<bool>>(growthTraps(scene_, eye));
        trapsEye_ = eye;
    }
    return traps_;
}

double CpuRenderer::intersect(std::uint32_t index, const Ray& ray, std::uint32_t fromSphere,
                              StartsOn start) const {
    const Sphere& s = scene_.spheres[index];
    const StartsOn mode = index == fromSphere ? start : StartsOn::Elsewhere;
    if (s.isTrueSphere) return intersectSphere(s.centre, s.radius, ray, mode);
    const dvec3 o = dvec3(s.objectFromWorld * glm::dvec4(ray.origin, 1.0));
    const glm::dmat3 m(s.objectFromWorld);
    const dvec3 d = m * ray.direction;
    // Rounding of o: of the origin through the matrix, and of the product.
    double matrixNorm = 0.0;
    for (int row = 0; row < 3; ++row)
        matrixNorm = std::max(matrixNorm, std::abs(m[0][row]) + std::abs(m[1][row]) + std::abs(m[2][row]));
    const double tolerance = kRounding * (glm::length(o) + 1.0 + matrixNorm * glm::length(ray.origin));
    return intersectUnitSphere(o, d, mode, tolerance);
}

bool CpuRenderer::closestHit(const Ray& ray, std::uint32_t fromSphere, StartsOn start, Hit& hit) const {
    hit = Hit{};
    auto test = [&](std::uint32_t i) {
        const double t = intersect(i, ray, fromSphere, start);
        if (t < hit.t) { hit.t = t; hit.sphere = i; }
    };
    if (!useBvh_) {
        for (std::uint32_t i = 0; i < scene_.spheres.size(); ++i) test(i);
        return hit.sphere != kNone;
    }
    const dvec3 inverseDir = 1.0 / ray.direction;
    std::uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const BvhNode& node = bvh_.nodes[stack[--top]];
        if (!rayHitsBox(node.bounds, ray.origin, inverseDir, hit.t)) continue;
        if (node.count > 0) {
            for (std::uint32_t k = 0; k < node.count; ++k) test(bvh_.order[node.first + k]);
        } else {
            stack[top++] = node.first;
            stack[top++] = node.first + 1;
        }
    }
    return hit.sphere != kNone;
}

bool CpuRenderer::occluded(const Ray& ray, double distance, std::uint32_t fromSphere, StartsOn start) const {
    // SPEC §4.3: blocked if a surface crosses the open segment (0, distance).
    // A ray that starts on a sphere headed into it (shading a hit from inside)
    // crosses that sphere at its chord unless the light is nearer: that one
    // test first spares the search its answer.
    if (start == StartsOn::Entering && intersect(fromSphere, ray, fromSphere, start) < distance) return true;
    if (!useBvh_) {
        for (std::uint32_t i = 0; i < scene_.spheres.size(); ++i)
            if (intersect(i, ray, fromSphere, start) < distance) return true;
        return false;
    }
    const dvec3 inverseDir = 1.0 / ray.direction;
    std::uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const BvhNode& node = bvh_.nodes[stack[--top]];
        if (!rayHitsBox(node.bounds, ray.origin, inverseDir, distance)) continue;
        if (node.count > 0) {
            for (std::uint32_t k = 0; k < node.count; ++k)
                if (intersect(bvh_.order[node.first + k], ray, fromSphere, start) < distance) return true;
        } else {
            stack[top++] = node.first;
            stack[top++] = node.first + 1;
        }
    }
    return false;
}

// SPEC §3: sub-pixel sample k = b·s + a of pixel (x, y): the ray through
// (x + (a + ½)/s, y + (b + ½)/s), from the eye.
CpuRenderer::PendingRay CpuRenderer::cameraRay(const Camera& camera, int s, int x, int y, int k) {
    const int a = k % s, b = k / s;
    const double px = x + (a + 0.5) / s;
    const double py = y + (b + 0.5) / s;
    PendingRay primary;
    primary.ray = {camera.eye, camera.direction(px, py)};
    return primary;
}

// The outward normal No of `sphere` at the point o + t d of `ray` (an
// ellipsoid's through its object frame: the transposed inverse map).
dvec3 CpuRenderer::outwardNormal(const Sphere& sphere, const Ray& ray, double t) const {
    if (sphere.isTrueSphere) return glm::normalize(ray.origin - sphere.centre + t * ray.direction);
    const dvec3 o = dvec3(sphere.objectFromWorld * glm::dvec4(ray.origin, 1.0));
    const dvec3 p = o + t * (glm::dmat3(sphere.objectFromWorld) * ray.direction);
    return glm::normalize(glm::transpose(glm::dmat3(sphere.objectFromWorld)) * p);
}

// 1–2. The closest hit of ray r (SPEC §4.1), and what shading needs there:
// the material, the point, and the shading normal N. False on a miss.
bool CpuRenderer::findHit(const PendingRay& r, Hit& hit) const {
    const StartsOn start = r.inward ? StartsOn::Entering : StartsOn::Leaving;
    if (!closestHit(r.ray, r.fromSphere, start, hit)) return false;
    const Sphere& sphere = scene_.spheres[hit.sphere];
    hit.material = &scene_.materials[sphere.material];
    // The hit point is o + t d, not re-projected (shaders/physics/hit.glsl says why).
    hit.point = r.ray.origin + hit.t * r.ray.direction;
    const dvec3 outward = outwardNormal(sphere, r.ray, hit.t);
    hit.fromOutside = glm::dot(r.ray.direction, outward) < 0.0;
    hit.normal = hit.fromOutside ? outward : -outward;
    return true;
}

// 3. The ambient part of the local term at a hit (SPEC §4.3).
dvec3 CpuRenderer::ambientTerm(const Hit& hit) const { return scene_.ambient * hit.material->kd; }

// Light's part of the local term at a hit, seen from v, with a binary shadow
// (SPEC §4.3); castShadowRay: a shadow ray was cast (the surface faces the light).
dvec3 CpuRenderer::shadeLight(const Light& light, const Hit& hit, const dvec3& v, const TraceSettings& settings,
                              bool& castShadowRay) const {
    castShadowRay = false;
    dvec3 l = light.position - hit.point;
    const double distance = glm::length(l);
    l /= distance;
    const double nl = glm::dot(hit.normal, l);
    if (!(nl > 0.0)) return dvec3(0.0);
    castShadowRay = settings.shadows;
    // A shadow ray towards N's side enters the sphere only when N = −No.
    const StartsOn start = hit.fromOutside ? StartsOn::Leaving : StartsOn::Entering;
    if (settings.shadows && occluded({hit.point, l}, distance, hit.sphere, start)) return dvec3(0.0);
    const Material& m = *hit.material;
    const dvec3 reflectedLight = 2.0 * nl * hit.normal - l;
    const double rv = glm::dot(reflectedLight, v);
    const double specular = rv > 0.0 ? std::pow(rv, m.phong) : 0.0;
    return light.colour * (m.kd * nl + m.ks * specular);
}

// The whole local term: ambient, then each light in order. (The shader adds
// each part to the pixel as it goes, so that a dispatch may stop between
// lights: the same terms, summed in another order.)
dvec3 CpuRenderer::localTerm(const Hit& hit, const dvec3& v, const TraceSettings& settings,
                             RayCounts& counts) const {
    dvec3 local = ambientTerm(hit);
    for (const Light& light : scene_.lights) {
        bool castShadowRay = false;
        const dvec3 term = shadeLight(light, hit, v, settings, castShadowRay);
        if (castShadowRay) ++counts.shadow;
        local += term;
    }
    return local;
}

// 4–5. The children of ray r at a hit (SPEC §4.4, §4.5): the reflected ray,
// keeping the medium stack, and the refracted ray by Snell's law, unless
// total internal reflection folds its weight into the reflected one.
CpuRenderer::Children CpuRenderer::children(const PendingRay& r, const Hit& hit,
                                            const TraceSettings& settings) const {
    const Material& m = *hit.material;
    const dvec3 d = r.ray.direction;
    Children c;
    dvec3 reflectedWeight = childWeight(r.weight, settings.reflection ? m.ks : dvec3(0.0));
    if (settings.refraction && m.refracts()) {
        const dvec3 transmittedWeight = childWeight(r.weight, m.kt);
        MediumStack media = r.media;
        const double eta = crossSurface(scene_, hit.fromOutside, m, hit.sphere, media);
        dvec3 refracted;
        if (!refractDirection(d, hit.normal, eta, refracted)) {
            // Total internal reflection is the reflected ray in the same
            // medium: one ray carrying both weights (exactly SPEC §4.5).
            reflectedWeight = glm::min(reflectedWeight + transmittedWeight, dvec3(kMaxWeight));
        } else {
            c.refracted = PendingRay{{hit.point, refracted}, transmittedWeight, r.depth + 1, hit.sphere,
                                     hit.fromOutside, true, media};
        }
    }
    c.reflected = PendingRay{{hit.point, reflectDirection(d, hit.normal)}, reflectedWeight, r.depth + 1, hit.sphere,
                             !hit.fromOutside, false, r.media};
    return c;
}

// Ray r of a tree, before its closest hit: the channels whose pixel sum has
// reached `saturation` are final in 8 bits (SPEC §4 amplifying materials) and
// dropped; under the cut-off it waits in tree.frontier for a lower one; past
// the tree budget it is lost (render/Truncation.h). Else it is traced.
bool CpuRenderer::admitRay(PendingRay& r, const dvec3& pixelSum, double saturation, double cutOff,
                           const TraceSettings& settings, RayCounts& counts, TreeTrace& tree) const {
    for (int k = 0; k < 3; ++k)
        if (pixelSum[k] >= saturation) r.weight[k] = 0.0;
    if (!worthTracing(r.weight, cutOff)) {
        tree.defer(std::move(r), settings);
        return false;
    }
    if (tree.budget != 0 && tree.rays >= tree.budget) {
        tree.overBudget = true;
        tree.lost += r.weight;
        return false;
    }
    ++tree.rays;
    tree.deepest = std::max(tree.deepest, r.depth);
    if (r.depth > 0) ++(r.refracted ? counts.refracted : counts.reflected);
    return true;
}

// What becomes of the children of ray r at a hit: the depth limit loses
// their weight (render/Truncation.h); under the cut-off a child waits in
// tree.frontier; the others go on `stack`, the one traced next last.
void CpuRenderer::followChildren(const PendingRay& r, const Hit& hit, double cutOff, const TraceSettings& settings,
                                 TreeTrace& tree, std::vector<PendingRay>& stack) const {
    const dvec3 gain = childrenGain(*hit.material, settings);
    if (r.depth >= settings.maxDepth) {
        tree.lost += weighted(r.weight, gain);
        return;
    }
    // Light carried into a material that traps it (SPEC §4 amplifying
    // materials; growthTraps: an orbit of total internal reflection that
    // gains at every bounce) grows until its channel saturates, and a path of
    // tiny weight that enters one does too. The pixel's series may diverge
    // behind steps that seem to settle, so its estimated error must be within
    // kAmplifiedEstimate and it goes on below the floor (renderPixel).
    if ((*tree.traps)[scene_.spheres[hit.sphere].material])
        for (int c = 0; c < 3; ++c)
            if (gain[c] > 1.0 && r.weight[c] > 0.0) tree.amplified = true;
    Children c = children(r, hit, settings);
    std::optional<PendingRay> refractedRay, reflectedRay;
    if (c.refracted) {
        if (worthTracing(c.refracted->weight, cutOff)) refractedRay = std::move(c.refracted);
        else tree.defer(std::move(*c.refracted), settings);
    }
    if (worthTracing(c.reflected.weight, cutOff)) reflectedRay = std::move(c.reflected);
    else tree.defer(std::move(c.reflected), settings);
    // The lighter child is traced next and the heavier waits (as the
    // shader does, whose stack this bounds: gpu/KernelPolicy.cpp); in an
    // amplifying scene the heavier goes first, so that a tree budget is
    // spent on the weightiest rays, those that saturate a diverging channel.
    if (reflectedRay && refractedRay &&
        (maxComponent(reflectedRay->weight) < maxComponent(refractedRay->weight)) != amplifying_)
        std::swap(reflectedRay, refractedRay);
    if (reflectedRay) stack.push_back(std::move(*reflectedRay));
    if (refractedRay) stack.push_back(std::move(*refractedRay));
}

// The ray tree (SPEC §4) below `root` (a camera ray, or a ray an earlier
// cut-off left), depth first with an explicit stack, each ray's local term
// added straight into pixelSum: the path of one ray, step for step the
// shader's main (shaders/trace.comp).
void CpuRenderer::traceTree(const PendingRay& root, dvec3& pixelSum, double saturation, double cutOff,
                            const TraceSettings& settings, RayCounts& counts, TreeTrace& tree) const {
    std::vector<PendingRay> stack;
    stack.push_back(root);
    while (!stack.empty()) {
        PendingRay r = std::move(stack.back());
        stack.pop_back();
        if (!admitRay(r, pixelSum, saturation, cutOff, settings, counts, tree)) continue;
        // 1–2. The closest hit; the background on a miss.
        Hit hit;
        if (!findHit(r, hit)) {
            addWeighted(pixelSum, r.weight, scene_.background);
            continue;
        }
        // 3. The local Phong term with binary shadows.
        addWeighted(pixelSum, r.weight, localTerm(hit, -r.ray.direction, settings, counts));
        // 4–5. The children: reflection, and refraction through the medium stack.
        followChildren(r, hit, cutOff, settings, tree, stack);
    }
}

CpuRenderer::Pixel CpuRenderer::renderPixel(const RenderRequest& request, int x, int y, RayCounts& counts) const {
    const int s = std::max(1, request.supersample);
    const int first = std::clamp(request.firstSample, 0, s * s - 1);
    const int count = request.sampleCount > 0 ? std::min(request.sampleCount, s * s - first) : s * s - first;
    const double samples = count;
    // Only amplifying scenes stop saturated channels: elsewhere the float
    // output keeps the whole unclamped sum (SPEC §6).
    const double saturation = amplifying_ ? samples : kNoHit;
    const TraceSettings& settings = request.trace;
    Pixel pixel;
    // The pixel's trees at the first cut-off; then, while its bound is over
    // the tolerance, the rays they left under the cut-off are traced on with
    // the next rung (nextRung, below the heaviest of them): together the very tree
    // one pass at that cut-off traces, with no ray traced twice. What each
    // step proves is kept (PixelEstimate).
    PixelEstimate estimate;
    ErrorEstimate change;
    dvec3 sum(0.0);
    TreeTrace tree;
    tree.budget = settings.treeBudget * std::uint64_t(count);
    const std::shared_ptr<const std::vector<bool>> traps = trapsFor(request.camera.eye);
    tree.traps = traps.get();
    tree.anyTrap = std::find(traps->begin(), traps->end(), true) != traps->end();
    const bool continues = settings.tolerance > 0.0;
    for (int k = first; k < first + count; ++k) {
        ++counts.primary;
        traceTree(cameraRay(request.camera, s, x, y, k), sum, saturation,
                  continues ? std::max(settings.minWeight, kFirstRung) : settings.minWeight, settings, counts, tree);
    }
    for (;;) {
        estimate.add(radiance_, sum, tree.lost + tree.deferred, samples);
        change.add(estimate.lower, tree.deferred * radiance_.local / samples);
        pixel.colour = estimate.lower;
        pixel.bound = estimate.bound();
        pixel.unbounded = estimate.unbounded();
        pixel.overBudget = tree.overBudget;
        pixel.deepest = tree.deepest;
        const bool within = pixel.bound <= settings.tolerance;
        pixel.overTolerance = continues && !within;
        // Done: certified; or nothing left under the cut-off (a lower one
        // would trace the same tree); or at the floor; or, where allowed, the
        // estimated error is within the tolerance.
        if (!continues || within || tree.frontier.empty()) break;
        const double error = change.error();
        // Kept for the bound image: terms >= 0, so it holds for later, larger colours.
        pixel.estimatedError = error;
        if (settings.estimate && pixel.unbounded && error <= settings.tolerance &&
            (!tree.amplified || error <= kAmplifiedEstimate)) {
            pixel.estimated = true;
            pixel.estimatedError = error;
            pixel.overTolerance = false;
            break;
        }
        // The next rung: kRungsDown below the heaviest ray the last step left,
        // not under the floor; but a pixel whose trees gained weight goes on
        // below it, until its diverging channels saturate or its trees reach
        // the budget (SPEC §4 amplifying materials).
        const bool belowFloor = tree.amplified && pixel.unbounded && tree.budget != 0;
        const double rung = nextRung(tree.heaviestDeferred);
        const double cutOff = belowFloor ? rung : std::max(settings.minWeight, rung);
        // Everything left is under the floor, or the budget is spent.
        if (cutOff > tree.heaviestDeferred || !(cutOff >= std::numeric_limits<float>::min()) || tree.overBudget) break;
        std::vector<PendingRay> waiting = std::move(tree.frontier);
        tree.frontier.clear();
        tree.deferred = dvec3(0.0);
        tree.heaviestDeferred = 0.0;
        for (const PendingRay& r : waiting) traceTree(r, sum, saturation, cutOff, settings, counts, tree);
    }
    return pixel;
}

Image CpuRenderer::render(const RenderRequest& request, RayCounts* counts) const {
    // The window rendered (the whole image unless asked), in bands of rows:
    // all of them at once for an image in memory, 32 at a time when the rows
    // stream to a sink. Pixel coordinates stay those of the whole image.
    const PixelWindow area = request.area();
    const int width = area.width(), height = area.height();
    const int bandRows = request.rowSink ? std::min(32, height) : height;
    Image band(width, bandRows);
    Image image = request.rowSink ? Image() : Image(width, height);
    const int threads = request.threads > 0
                            ? request.threads
                            : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    std::vector<RayCounts> perThread(threads);
    std::vector<TruncationReport> truncation(threads);
    request.startTruncationImages(static_cast<std::size_t>(width) * height);
    std::atomic<int> rowsDone{0};
    std::atomic<std::uint64_t> raysTraced{0};
    for (int bandStart = 0; bandStart < height; bandStart += bandRows) {
        const int rows = std::min(bandRows, height - bandStart);
        Image& target = request.rowSink ? band : image;
        const int targetOffset = request.rowSink ? bandStart : 0;
        std::atomic<int> nextRow{bandStart};
        auto work = [&](int id) {
            RayCounts& local = perThread[id];
            std::uint64_t raysBefore = local.total();
            for (int row; (row = nextRow.fetch_add(1)) < bandStart + rows;) {
                if (request.cancel && request.cancel->load()) return;
                const int y = area.y0 + row;
                for (int column = 0; column < width; ++column) {
                    const int x = area.x0 + column;
                    const Pixel pixel = renderPixel(request, x, y, local);
                    const dvec3 c = pixel.colour;
                    TruncationReport& t = truncation[id];
                    PixelTruncation outcome;
                    outcome.x = x;
                    outcome.y = y;
                    outcome.bound = pixel.bound;
                    outcome.unbounded = pixel.unbounded;
                    outcome.overBudget = pixel.overBudget;
                    outcome.overTolerance = pixel.overTolerance;
                    outcome.estimated = pixel.estimated;
                    outcome.estimatedError = pixel.estimatedError;
                    t.add(outcome);
                    t.deepest = std::max(t.deepest, pixel.deepest);
                    request.recordTruncation(static_cast<std::size_t>(row) * width + column, outcome);
                    float* p = target.pixel(column, row - targetOffset);
                    p[0] = static_cast<float>(c.x);
                    p[1] = static_cast<float>(c.y);
                    p[2] = static_cast<float>(c.z);
                }
                const int done = rowsDone.fetch_add(1) + 1;
                const std::uint64_t rays = raysTraced.fetch_add(local.total() - raysBefore) + local.total() - raysBefore;
                raysBefore = local.total();
                if (request.progress) request.progress(static_cast<double>(done) / height, rays);
            }
        };
        std::vector<std::thread> pool;
        for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
        work(0);
        for (std::thread& t : pool) t.join();
        if (request.cancel && request.cancel->load()) break;
        if (request.rowSink) request.rowSink(band.rgb.data(), rows);
    }
    if (request.truncation) {
        *request.truncation = TruncationReport{};
        for (const TruncationReport& t : truncation) request.truncation->merge(t);
    }
    if (counts) {
        *counts = RayCounts{};
        for (const RayCounts& c : perThread) {
            counts->primary += c.primary;
            counts->shadow += c.shadow;
            counts->reflected += c.reflected;
            counts->refracted += c.refracted;
        }
    }
    return image;
}

}  // namespace snell
