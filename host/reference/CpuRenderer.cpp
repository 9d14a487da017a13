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

}  // namespace

// Where a ray met its closest surface, and what shading needs there.
struct CpuRenderer::Hit {
    double t = kNoHit;
    std::uint32_t sphere = kNone;
    const Material* material = nullptr;
    dvec3 point{0.0};
    dvec3 normal{0.0};         // the shading normal N (against the ray)
    bool fromOutside = false;  // the ray arrived from outside the sphere
    double pointOff = 0.0;     // how far the point and the normal may be from the
    double normalOff = 0.0;    // exact ray's (Margins.h)
    double rounding = 0.0;     // of the point itself, and how fast the normal turns
    double turning = 0.0;      // with it (outwardNormal)
    double viewTilt = 0.0;     // how far the ray's direction, V of shading, may be turned from the exact one's
    bool undecided = false;    // the exact ray may meet another surface, none, or this one from its other side
};

struct CpuRenderer::PendingRay {
    Ray ray;
    dvec3 weight{1.0};
    int depth = 0;
    std::uint32_t fromSphere = kNone;  // the sphere whose surface the ray starts on
    bool inward = false;               // it starts into that sphere
    bool refracted = false;
    MediumStack media;
    margins::Uncertainty off;  // how far it may be from the exact ray (Margins.h)
    bool covered = false;      // an undecided ancestor's widening already covers its light
};

// One hit's children: the reflected ray, and the refracted one unless total
// internal reflection (or no refraction) leaves none.
struct CpuRenderer::Children {
    PendingRay reflected;
    std::optional<PendingRay> refracted;
    bool undecided = false;  // total internal reflection or not is within its margin
};

// What a pixel's trees did not trace so far (render/Truncation.h): the weight
// lost for good (depth limit, tree budget) and the rays left under the cut-off
// (`frontier`, which a lower cut-off continues from); how many rays they traced
// and how deep they went.
struct CpuRenderer::TreeTrace {
    dvec3 lost{0.0};              // the most light of the rays lost
    dvec3 deferred{0.0};          // the weight of the rays in `frontier`
    dvec3 deferredLight{0.0};     // and the most light they can bring (render/Reach.h)
    double heaviestDeferred = 0.0;
    std::vector<PendingRay> frontier;
    std::uint64_t rays = 0;
    std::uint64_t budget = 0;     // the most rays they may trace; 0: no limit
    int deepest = 0;
    bool overBudget = false;
    bool amplified = false;       // a hit met a trap (growthTraps) with light of a gain > 1
    const std::vector<bool>* traps = nullptr;  // per material (growthTraps)
    const RadianceBound* radiance = nullptr;
    const ReachBound* reach = nullptr;
    bool inwardHolds = false;  // reach->inward holds for this render's eye
    bool anyTrap = false;
    // Where a decision was undecided (Margins.h): the weight of the rays whose
    // light either outcome may change (each by at most its weight times R),
    // and the light of terms that may be off (shadow rays, shading's rounding).
    dvec3 undecidedReach{0.0};  // of rays: their weights times their reach
    dvec3 undecidedLight{0.0};
    bool undecided = false;
    // The light the pixel's sum holds that the exact tree's may not, largest
    // channel (render/Truncation.h, whiteEitherWay): covered rays', and of
    // the others' terms what the exact ones may lack.
    double excess = 0.0;

    // Ray r's light, added to the pixel's sum; `excess` of it as above.
    void add(dvec3& pixelSum, const PendingRay& r, const dvec3& light, const dvec3& unsure) {
        addWeighted(pixelSum, r.weight, light);
        excess += maxComponent(weighted(r.weight, r.covered ? light : unsure));
    }

    // Ray r's light below this point may be either outcome's.
    void widen(PendingRay& r, const dvec3& weight) {
        undecided = true;
        if (!r.covered) undecidedReach += weighted(weight, reachOf(r));
        r.covered = true;
    }

    // The most light ray r can bring, per unit weight (render/Reach.h): by
    // where it starts, or R for a camera ray and one whose light may be
    // either outcome's of an undecided decision.
    dvec3 reachOf(const PendingRay& r) const {
        return r.covered || r.fromSphere == kNone ? radiance->radiance : sphereReach(r.fromSphere, r.inward);
    }
    dvec3 sphereReach(std::uint32_t sphere, bool inward) const {
        if (!inward) return reach->outward[sphere];
        return inwardHolds ? reach->inward[sphere] : radiance->radiance;
    }
    void lose(const PendingRay& r) { lost += weighted(r.weight, reachOf(r)); }

    // A ray under the cut-off: the next, lower cut-off starts from it (under
    // the floor no cut-off will, and it is lost; but in a scene with traps a
    // pixel may go below the floor, renderPixel).
    void defer(PendingRay&& r, const TraceSettings& settings) {
        const double m = maxComponent(r.weight);
        if (!(m > 0.0)) return;
        const bool mayGoBelowFloor = anyTrap && settings.treeBudget != 0;
        if (!(settings.tolerance > 0.0) || (m < settings.minWeight && !mayGoBelowFloor)) {
            lose(r);
            return;
        }
        deferred += r.weight;
        deferredLight += weighted(r.weight, reachOf(r));
        heaviestDeferred = std::max(heaviestDeferred, m);
        frontier.push_back(std::move(r));
    }
};

CpuRenderer::CpuRenderer(const Scene& scene) : scene_(scene) {
    amplifying_ = scene.anyAmplifying();
    radiance_ = radianceBound(scene);
    reach_ = reachBound(scene, radiance_);
    useBvh_ = scene.spheres.size() > kBvhThreshold;
    if (useBvh_) {
        std::vector<Aabb> bounds;
        bounds.reserve(scene.spheres.size());
        for (const Sphere& s : scene.spheres) bounds.push_back(sphereBounds(s));
        bvh_ = buildBvh(bounds);
    }
}

std::shared_ptr<const std::vector<bool>> CpuRenderer::trapsFor(const dvec3& eye, bool& inward) const {
    const std::lock_guard<std::mutex> lock(trapsMutex_);
    if (!traps_ || trapsEye_ != eye) {
        traps_ = std::make_shared<const std::vector<bool>>(growthTraps(scene_, eye));
        inwardHolds_ = inwardHolds(scene_, reach_.hollow, eye);
        trapsEye_ = eye;
    }
    inward = inwardHolds_;
    return traps_;
}

// SPEC §3: sub-pixel sample k = b·s + a of pixel (x, y): the ray through
// (x + (a + ½)/s, y + (b + ½)/s), from the eye.
CpuRenderer::PendingRay CpuRenderer::cameraRay(const Camera& camera, int s, int x, int y, int k) {
    const int a = k % s, b = k / s;
    const double px = x + (a + 0.5) / s;
    const double py = y + (b + 0.5) / s;
    PendingRay primary;
    primary.ray = {camera.eye, camera.direction(px, py)};
    primary.off = {margins::kChain * kUnitRoundoff * glm::length(camera.eye), margins::kChain * kUnitRoundoff};
    return primary;
}

// The outward normal No of `sphere` at the point o + t d of `ray` (an
// ellipsoid's through its object frame: the transposed inverse map), and how
// much an offset of the point turns it (Margins.h, normalOff): 1/r on a true
// sphere; on an ellipsoid, where n = Mᵀ M x, the part of Mᵀ M δ across n over
// |n|, which at most ‖(I − N Nᵀ) Mᵀ M‖ (Frobenius) δ / |n| (Margins.h, turning).
dvec3 CpuRenderer::outwardNormal(const Sphere& sphere, const Ray& ray, double t, double& turning) const {
    if (sphere.isTrueSphere) {
        turning = 1.0 / sphere.radius;
        return glm::normalize(ray.origin - sphere.centre + t * ray.direction);
    }
    const dvec3 o = dvec3(sphere.objectFromWorld * glm::dvec4(ray.origin, 1.0));
    const dvec3 p = o + t * (glm::dmat3(sphere.objectFromWorld) * ray.direction);
    const glm::dmat3 m(sphere.objectFromWorld);
    const dvec3 normal = glm::transpose(m) * p;
    turning = margins::turning(glm::transpose(m) * m, normal);
    return glm::normalize(normal);
}

// 1–2. The closest hit of ray r (SPEC §4.1), and what shading needs there:
// the material, the point, and the shading normal N. False on a miss.
bool CpuRenderer::findHit(const PendingRay& r, Hit& hit) const {
    const StartsOn start = r.inward ? StartsOn::Entering : StartsOn::Leaving;
    // A covered ray's light is already its ancestor's widening: its decisions
    // count for nothing, so it keeps no offset (as the shader's findHit).
    const margins::Uncertainty off = r.covered ? margins::Uncertainty{} : r.off;
    const Closest closest = closestHit(r.ray, r.fromSphere, start, off);
    hit.t = closest.t;
    hit.sphere = closest.sphere;
    hit.undecided = closest.undecided;
    if (closest.sphere == kNone) return false;
    const Sphere& sphere = scene_.spheres[hit.sphere];
    hit.material = &scene_.materials[sphere.material];
    // The hit point is o + t d, not re-projected (shaders/physics/hit.glsl says why).
    hit.point = r.ray.origin + hit.t * r.ray.direction;
    double turning = 0.0;
    const dvec3 outward = outwardNormal(sphere, r.ray, hit.t, turning);
    const double facing = glm::dot(r.ray.direction, outward);
    hit.fromOutside = facing < 0.0;
    hit.normal = hit.fromOutside ? outward : -outward;
    // How sure: the point, its normal, and which side the ray came from.
    hit.rounding = margins::kChain * kUnitRoundoff * (glm::length(r.ray.origin) + hit.t);
    hit.turning = turning;
    hit.pointOff = closest.margin + hit.rounding;
    hit.normalOff = margins::normalOff(hit.pointOff, turning, kUnitRoundoff);
    hit.viewTilt = off.tilt;
    if (std::abs(facing) <= margins::facingMargin(off.tilt, hit.normalOff, kUnitRoundoff)) hit.undecided = true;
    return true;
}

// 3. The ambient part of the local term at a hit (SPEC §4.3).
dvec3 CpuRenderer::ambientTerm(const Hit& hit) const { return scene_.ambient * hit.material->kd; }

// Light's part of the local term at a hit, seen from v, with a binary shadow
// (SPEC §4.3); castShadowRay: a shadow ray was cast (the surface faces the light).
dvec3 CpuRenderer::shadeLight(const Light& light, const Hit& hit, const dvec3& v, const TraceSettings& settings,
                              bool& castShadowRay, Uncertain& uncertain) const {
    castShadowRay = false;
    dvec3 l = light.position - hit.point;
    const double distance = glm::length(l);
    l /= distance;
    const double nl = glm::dot(hit.normal, l);
    if (!(nl > 0.0)) return dvec3(0.0);
    castShadowRay = settings.shadows;
    // A shadow ray towards N's side enters the sphere only when N = −No.
    const StartsOn start = hit.fromOutside ? StartsOn::Leaving : StartsOn::Entering;
    const margins::Uncertainty toLight{hit.pointOff, hit.pointOff / distance + margins::kChain * kUnitRoundoff};
    bool undecided = false;
    const bool blocked = settings.shadows && occluded({hit.point, l}, distance, hit.sphere, start, toLight, undecided);
    const Material& m = *hit.material;
    const dvec3 reflectedLight = 2.0 * nl * hit.normal - l;
    const double rv = glm::dot(reflectedLight, v);
    const double specular = rv > 0.0 ? std::pow(rv, m.phong) : 0.0;
    const dvec3 term = light.colour * (m.kd * nl + m.ks * specular);
    // Either side of a shadow's edge; and N·L and R·V off by the normal's and
    // the direction's uncertainty: kd·δ, and (R·V)^p's (Margins.h, specularOff).
    if (undecided) {
        uncertain.light += term;
        uncertain.undecided = true;
        if (!blocked) uncertain.excess += term;
    }
    const double cosineOff = 2.0 * (hit.normalOff + toLight.tilt) + hit.viewTilt + margins::kChain * kUnitRoundoff;
    const double specularOff = margins::specularOff(rv, m.phong, cosineOff, specular, 0.0);
    if (!blocked) {
        const dvec3 error = light.colour * (m.kd * cosineOff + m.ks * specularOff);
        uncertain.light += error;
        uncertain.excess += error;
    }
    return blocked ? dvec3(0.0) : term;
}

// The whole local term: ambient, then each light in order. (The shader adds
// each part to the pixel as it goes, so that a dispatch may stop between
// lights: the same terms, summed in another order.)
dvec3 CpuRenderer::localTerm(const Hit& hit, const dvec3& v, const TraceSettings& settings, RayCounts& counts,
                             Uncertain& uncertain) const {
    dvec3 local = ambientTerm(hit);
    for (const Light& light : scene_.lights) {
        bool castShadowRay = false;
        const dvec3 term = shadeLight(light, hit, v, settings, castShadowRay, uncertain);
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
    const margins::Hand hand{hit.pointOff, hit.t, hit.rounding, hit.turning, hit.fromOutside};
    // Under a covered ray the children keep no offset either (findHit).
    const bool keeps = !r.covered;
    const margins::Uncertainty none{};
    dvec3 reflectedWeight = childWeight(r.weight, settings.reflection ? m.ks : dvec3(0.0));
    if (settings.refraction && m.refracts()) {
        const dvec3 transmittedWeight = childWeight(r.weight, m.kt);
        MediumStack media = r.media;
        const double eta = crossSurface(scene_, hit.fromOutside, m, hit.sphere, media);
        dvec3 refracted;
        const double cosine = -glm::dot(hit.normal, d);
        const double k = 1.0 - eta * eta * (1.0 - cosine * cosine);  // refractDirection's
        c.undecided = std::abs(k) <= margins::reflectionMargin(eta, r.off.tilt + hit.normalOff, kUnitRoundoff);
        if (!refractDirection(d, hit.normal, eta, refracted)) {
            // Total internal reflection is the reflected ray in the same
            // medium: one ray carrying both weights (exactly SPEC §4.5).
            reflectedWeight = glm::min(reflectedWeight + transmittedWeight, dvec3(kMaxWeight));
        } else {
            c.refracted = PendingRay{{hit.point, refracted}, transmittedWeight, r.depth + 1, hit.sphere,
                                     hit.fromOutside, true, media,
                                     keeps ? margins::refracted(r.off, hand, eta, k, kUnitRoundoff) : none,
                                     r.covered};
        }
    }
    c.reflected = PendingRay{{hit.point, reflectDirection(d, hit.normal)}, reflectedWeight, r.depth + 1, hit.sphere,
                             !hit.fromOutside, false, r.media,
                             keeps ? margins::reflected(r.off, hand, kUnitRoundoff) : none, r.covered};
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
        tree.lose(r);
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
        tree.lost += weighted(weighted(r.weight, gain), radiance_.radiance);
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
    if (c.undecided && !r.covered) {
        // Reflected or refracted: either outcome's children carry light
        // within their weights times R (as the shader, whose followChildren
        // does not read their sphere's reach).
        tree.undecided = true;
        tree.undecidedReach += weighted(weighted(r.weight, gain), radiance_.radiance);
        c.reflected.covered = true;
        if (c.refracted) c.refracted->covered = true;
    }
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
        // 1–2. The closest hit; the background on a miss. Where rounding may
        // have chosen it, the light of the ray is either outcome's.
        Hit hit;
        const bool met = findHit(r, hit);
        if (hit.undecided) tree.widen(r, r.weight);
        if (!met) {
            tree.add(pixelSum, r, scene_.background, dvec3(0.0));
            continue;
        }
        // 3. The local Phong term with binary shadows.
        Uncertain uncertain;
        const dvec3 local = localTerm(hit, -r.ray.direction, settings, counts, uncertain);
        tree.add(pixelSum, r, local, uncertain.excess);
        if (!r.covered) tree.undecidedLight += weighted(r.weight, uncertain.light);
        tree.undecided = tree.undecided || uncertain.undecided;
        // 4–5. The children: reflection, and refraction through the medium stack.
        followChildren(r, hit, cutOff, settings, tree, stack);
    }
}

CpuRenderer::Pixel CpuRenderer::renderPixel(const RenderRequest& request, int x, int y, RayCounts& counts,
                                            std::uint64_t sampleMask) const {
    const int s = std::max(1, request.supersample);
    const int first = std::clamp(request.firstSample, 0, s * s - 1);
    const int all = request.sampleCount > 0 ? std::min(request.sampleCount, s * s - first) : s * s - first;
    auto traced = [&](int k) { return sampleMask == 0 || (k - first < 64 && ((sampleMask >> (k - first)) & 1u) != 0); };
    int count = 0;
    for (int k = first; k < first + all; ++k) count += traced(k) ? 1 : 0;
    const double samples = std::max(count, 1);
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
    bool inward = false;
    const std::shared_ptr<const std::vector<bool>> traps = trapsFor(request.camera.eye, inward);
    tree.traps = traps.get();
    tree.anyTrap = std::find(traps->begin(), traps->end(), true) != traps->end();
    tree.radiance = &radiance_;
    tree.reach = &reach_;
    tree.inwardHolds = inward;
    const bool continues = settings.tolerance > 0.0;
    for (int k = first; k < first + all; ++k) {
        if (!traced(k)) continue;
        ++counts.primary;
        traceTree(cameraRay(request.camera, s, x, y, k), sum, saturation,
                  continues ? std::max(settings.minWeight, kFirstRung) : settings.minWeight, settings, counts, tree);
    }
    for (;;) {
        estimate.add(sum, tree.lost + tree.deferredLight, samples);
        change.add(estimate.lower, tree.deferred * radiance_.local / samples);
        pixel.colour = estimate.lower;
        pixel.bound = estimate.bound();
        pixel.unbounded = estimate.unbounded();
        pixel.overBudget = tree.overBudget;
        pixel.deepest = tree.deepest;
        const bool within = pixel.bound <= settings.tolerance;
        pixel.overTolerance = continues && !within;
        const double error = change.error();
        const bool estimateWithin =
            settings.estimate && error <= settings.tolerance && (!tree.amplified || error <= kAmplifiedEstimate);
        // A bounded pixel that ends over the tolerance states its estimate,
        // where that is within it, beside its bound (set here, undone below
        // where it goes on).
        pixel.estimated = pixel.overTolerance && !pixel.unbounded && estimateWithin;
        if (pixel.estimated) {
            pixel.estimatedError = error;
            pixel.overTolerance = false;
        }
        // Done: certified; or nothing left under the cut-off (a lower one
        // would trace the same tree); or at the floor; or, where allowed, the
        // estimated error is within the tolerance.
        if (!continues || within || tree.frontier.empty()) break;
        // Kept for the bound image: terms >= 0, so it holds for later, larger colours.
        pixel.estimatedError = error;
        if (pixel.unbounded && estimateWithin) {
            pixel.estimated = true;
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
        pixel.estimated = false;
        pixel.overTolerance = continues;
        std::vector<PendingRay> waiting = std::move(tree.frontier);
        tree.frontier.clear();
        tree.deferred = tree.deferredLight = dvec3(0.0);
        tree.heaviestDeferred = 0.0;
        for (const PendingRay& r : waiting) traceTree(r, sum, saturation, cutOff, settings, counts, tree);
    }
    // Where a decision was undecided, or rounding may have moved a term, the
    // exact colour may lie on either side: the bound widens by that light
    // (Margins.h), and by the rounding of the sums and of the weights (each
    // at most `deepest` + lights + a few rounded factors or terms). Where the
    // reach is infinite an undecided ray's light has no bound: nor has the pixel,
    // but the clamp, and it claims no estimate.
    const double terms = tree.deepest + double(scene_.lights.size()) + 4.0;
    const double rounding =
        margins::kChain * kUnitRoundoff * terms * (maxComponent(glm::abs(pixel.colour)) + pixel.bound);
    const dvec3 spread = tree.undecidedReach + tree.undecidedLight;
    pixel.widening = maxComponent(spread) / samples + rounding;
    pixel.gap = maxComponent(estimate.upper - estimate.lower);
    // White whichever way its decisions went: the exact pixel is white too,
    // and its bound stays (its widening is kept for a pixel some of whose
    // samples these are: TileReadback.cpp, combineSamples).
    const bool white = whiteEitherWay(pixel.colour, tree.excess / samples + rounding);
    pixel.undecided = tree.undecided && !white;
    if (white) return pixel;
    if (std::isfinite(pixel.widening)) {
        pixel.bound = std::min(1.0, pixel.bound + pixel.widening);
    } else {
        pixel.bound = std::max(pixel.bound, clampOnlyBound(pixel.colour));
        pixel.unbounded = true;
        pixel.estimated = false;
        pixel.estimatedError = std::numeric_limits<double>::infinity();
    }
    return pixel;
}

}  // namespace snell
