#include "check/SceneCheck.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "bvh/Bvh.h"
#include "common/Json.h"
#include "reference/CpuRenderer.h"

namespace snell {

namespace {

bool inside(const Sphere& s, const dvec3& p) {
    const dvec3 o = dvec3(s.objectFromWorld * glm::dvec4(p, 1.0));
    return glm::dot(o, o) < 1.0;
}

std::string vec(const dvec3& v) {
    std::ostringstream s;
    s << v.x << " " << v.y << " " << v.z;
    return s.str();
}

}  // namespace

namespace {

// A warning about the scene as a whole: no position (Diagnostic::format).
Diagnostic aboutFile(const std::string& path, std::string message) {
    Diagnostic d;
    d.location.file = path;
    d.location.line = d.location.column = 0;
    d.message = std::move(message);
    return d;
}

// Repeated warnings of one kind: the first few, then how many more.
class WarningList {
public:
    explicit WarningList(std::vector<Diagnostic>& out) : out_(out) {}
    void add(const SourceLocation& at, const std::string& message, const std::string& kind) {
        if (++counts_[kind] <= kMaxPerKind) out_.push_back({at, message});
        else lastFile_ = at.file;
    }
    void summarize(const std::string& kind, const std::string& what) {
        if (counts_[kind] > kMaxPerKind)
            out_.push_back(aboutFile(lastFile_, std::to_string(counts_[kind] - kMaxPerKind) + " more " + what + " not shown"));
    }

private:
    static constexpr int kMaxPerKind = 10;
    std::vector<Diagnostic>& out_;
    std::map<std::string, int> counts_;
    std::string lastFile_;
};

// Wholly behind the eye's plane: no camera ray can reach it (reflections may).
bool behindCamera(const Sphere& s, const Camera& camera) {
    const Aabb b = sphereBounds(s);
    for (int corner = 0; corner < 8; ++corner) {
        const dvec3 p{corner & 1 ? b.upper.x : b.lower.x, corner & 2 ? b.upper.y : b.lower.y,
                      corner & 4 ? b.upper.z : b.lower.z};
        if (glm::dot(p - camera.eye, camera.forward) >= 0.0) return false;
    }
    return true;
}

// Returns how many spheres are behind the camera.
std::size_t warnAboutSpheres(const Scene& scene, const std::string& path, std::vector<Diagnostic>& out) {
    // Lights inside spheres: every pair, unless that is too much work for a warning.
    constexpr double kMaxPairs = 5e7;
    const bool pairs = double(scene.spheres.size()) * double(scene.lights.size()) <= kMaxPairs;
    const Camera camera = Camera::fromSpec(std::max(1, scene.imageSize), scene.halfWidth);
    WarningList list(out);
    std::size_t behind = 0;
    for (const Sphere& s : scene.spheres) {
        const SourceLocation at{path, s.location.line, s.location.column};
        for (std::size_t j = 0; pairs && j < scene.lights.size(); ++j) {
            if (inside(s, scene.lights[j].position))
                list.add(at, "light " + std::to_string(j + 1) + " (at " + vec(scene.lights[j].position) +
                                 ") is inside this sphere, so it lights only the sphere's inside (shadows are "
                                 "binary: a transparent sphere blocks light too); move the light out of it",
                         "light");
        }
        if (behindCamera(s, camera)) {
            ++behind;
            list.add(at, "this sphere is behind the camera (only reflections can show it); the camera looks "
                         "down -z from (0, 0, 1)",
                     "behind");
        }
    }
    list.summarize("light", "lights inside spheres");
    list.summarize("behind", "spheres behind the camera");
    return behind;
}

void warnAboutEmptyView(const Scene& scene, const std::string& path, std::size_t behind,
                        std::vector<Diagnostic>& out) {
    if (behind == scene.spheres.size())
        out.push_back(aboutFile(path, std::string(scene.spheres.empty() ? "the scene has no sphere"
                                                                         : "every sphere is behind the camera") +
                                          ": the image will be the background colour; spheres in front of the "
                                          "camera have z < 1 (the eye is at (0, 0, 1), looking down -z)"));
}

// SPEC §4: a renderer warns of a material with ks + kt > 1 and says that its
// float output where light diverges is a partial sum. Once a material, at its
// first sphere.
void warnAboutAmplifyingMaterials(const Scene& scene, const std::string& path, std::vector<Diagnostic>& out) {
    std::vector<bool> seen(scene.materials.size(), false);
    WarningList list(out);
    for (const Sphere& s : scene.spheres) {
        const Material& m = scene.materials[s.material];
        if (seen[s.material] || !m.amplifies()) continue;
        seen[s.material] = true;
        char text[400];
        std::snprintf(text, sizeof text,
                      "the material of this sphere has ks + kt = %g in a channel, above 1: light can grow from "
                      "bounce to bounce, and where a pixel's sum diverges its 8-bit value is 255 and a float "
                      "image (.pfm, .exr) holds a partial sum; keep ks + kt <= 1 in every channel for light that fades",
                      m.largestGain());
        list.add({path, s.location.line, s.location.column}, text, "amplifying");
    }
    list.summarize("amplifying", "spheres of other amplifying materials");
}

// The warnings at lines of the file: the parser's, and those of its spheres.
// Returns how many spheres are behind the camera.
std::size_t warnAboutLines(const Scene& scene, const std::string& path, std::vector<Diagnostic>& out) {
    out.insert(out.end(), scene.warnings.begin(), scene.warnings.end());
    const std::size_t behind = warnAboutSpheres(scene, path, out);
    warnAboutAmplifyingMaterials(scene, path, out);
    return behind;
}

// Line by line as a compiler reports; those about the whole file after them.
std::vector<Diagnostic> inLineOrder(std::vector<Diagnostic> warnings) {
    auto key = [](const Diagnostic& d) {
        return std::pair(d.location.line > 0 ? d.location.line : std::numeric_limits<int>::max(), d.location.column);
    };
    std::stable_sort(warnings.begin(), warnings.end(),
                     [&key](const Diagnostic& a, const Diagnostic& b) { return key(a) < key(b); });
    return warnings;
}

// No light and no ambient: the spheres' own terms are black, and they can
// only show the background through reflection and refraction.
void warnAboutDarkness(const Scene& scene, const std::string& path, std::vector<Diagnostic>& out) {
    const bool lit = std::any_of(scene.lights.begin(), scene.lights.end(),
                                 [](const Light& l) { return l.colour != dvec3(0.0); });
    if (lit || scene.ambient != dvec3(0.0) || scene.spheres.empty()) return;
    const bool showsBackground = scene.background != dvec3(0.0) && (scene.anyReflection() || scene.anyRefraction());
    out.push_back(aboutFile(path, std::string("no light and no ambient: every sphere renders black") +
                                      (showsBackground ? " except where it reflects or refracts the background" : "") +
                                      "; add a 'light r g b x y z' or an 'ambient r g b'"));
}

// Rays a pixel's tree traces at `trace`, counted by the CPU reference on
// `sample` x `sample` pixels spread over the pixels the render traces (their
// centres): the camera of the whole image, its pixels stretched to cover
// the shape's area in `sample` steps each way.
double raysPerPixel(const CpuRenderer& reference, const Scene& scene, const RenderShape& shape, int sample,
                    TraceSettings trace) {
    const PixelWindow area = shape.area();
    RenderRequest r;
    r.width = std::min(sample, area.width());
    r.height = std::min(sample, area.height());
    const Camera whole = Camera::fromSpec(shape.size, scene.halfWidth);
    r.camera = whole;
    r.camera.cornerDir = whole.cornerDir + double(area.x0) * whole.pixelRight + double(area.y0) * whole.pixelDown;
    r.camera.pixelRight = whole.pixelRight * (double(area.width()) / r.width);
    r.camera.pixelDown = whole.pixelDown * (double(area.height()) / r.height);
    r.supersample = shape.supersample;
    // A runaway tree (no budget) would never end the count: count a budget's worth.
    if (trace.treeBudget == 0) trace.treeBudget = kDefaultSettings.treeBudget;
    r.trace = trace;
    RayCounts rays;
    reference.render(r, &rays);
    return double(rays.total()) / (double(r.width) * r.height);
}

constexpr int kCostSample = 8;  // 8 x 8 pixels spread over the image

// The reference that counts the samples' rays, built (BVH and all) once for
// both warnings that need it, and only where one does.
class SampleReference {
public:
    explicit SampleReference(const Scene& scene) : scene_(scene) {}
    const CpuRenderer& get() {
        if (!reference_) reference_.emplace(scene_);
        return *reference_;
    }

private:
    const Scene& scene_;
    std::optional<CpuRenderer> reference_;
};

// Many rays make a render expensive: say so before it starts, with the size
// that previews it cheaply. The rays are counted, not guessed from the
// image's size: 8192² of one sphere is 8e7 rays and about a second on
// 2-core lavapipe; SphereFlake4's own 10000² is 7e8 rays and minutes. The
// count needs the reference's BVH, whose build outweighs the rest of
// `check` beyond some thousands of spheres (at 10^6 it took `check` from
// 0.8 to 2.2 s): there the camera rays alone, a lower bound, stand in.
bool warnAboutCost(const Scene& scene, const RenderShape& shape, const std::string& path, SampleReference& reference,
                   std::vector<Diagnostic>& out) {
    constexpr double kManyRays = 4e8;  // 3 s to 2.5 min at lavapipe's 1.3-70 Mrays/s a core, on 2 cores
    constexpr double kPreviewCameraRays = 1 << 20;  // 1024 x 1024 at one sample
    constexpr std::size_t kMaxCountedSpheres = 16384;  // a BVH build of some 20 ms
    const PixelWindow area = shape.area();
    const double pixels = double(area.width()) * area.height();
    const double cameraRays = pixels * shape.supersample * shape.supersample;
    if (scene.spheres.empty() || cameraRays <= kPreviewCameraRays) return false;
    const bool counted = scene.spheres.size() <= kMaxCountedSpheres;
    const double perPixel = counted ? raysPerPixel(reference.get(), scene, shape, kCostSample, shape.trace)
                                    : double(shape.supersample) * shape.supersample;
    const double total = perPixel * pixels;
    if (total <= kManyRays) return false;
    const int previewSize = std::max(1, int(std::sqrt(kPreviewCameraRays) / shape.supersample));
    const double previewPixels = double(previewSize) * previewSize;
    const bool whole = area == PixelWindow{0, 0, shape.size, shape.size};
    char pixelsText[100];
    std::snprintf(pixelsText, sizeof pixelsText, whole ? "%dx%d pixels" : "%dx%d pixels of the region",
                  area.width(), area.height());
    char how[250];
    if (counted)
        std::snprintf(how, sizeof how, "about %.2g rays (%s, %.1f rays a pixel on %dx%d of them, counted with the CPU "
                      "reference)", total, pixelsText, perPixel, std::min(kCostSample, area.width()),
                      std::min(kCostSample, area.height()));
    else
        std::snprintf(how, sizeof how, "at least %.2g rays (%s, %d camera rays each)", total, pixelsText,
                      shape.supersample * shape.supersample);
    char text[600];
    std::snprintf(text, sizeof text,
                  "this render traces %s; a CPU Vulkan driver traces 1 to 70 million rays a second a core, the "
                  "fewer the more spheres a ray passes; --size %d%s previews it %.0fx faster",
                  how, previewSize, whole ? "" : " without --region", pixels / previewPixels);
    out.push_back(aboutFile(path, text));
    return true;
}

// Light in materials with ks + kt > 1 is followed at the defaults until it
// saturates (SPEC §4): measure what that costs on a sparse sample of the
// image, with the reference, against POV-Ray's fixed tree.
bool warnAboutAmplifying(const Scene& scene, const RenderShape& shape, const std::string& path,
                         SampleReference& reference, std::vector<Diagnostic>& out) {
    constexpr int kSample = kCostSample;
    constexpr double kManyRays = 1e8;       // seconds on a CPU Vulkan driver
    if (!shape.defaultTree || !scene.anyAmplifying() || scene.spheres.empty() || shape.size <= 0) return false;
    const PixelWindow area = shape.area();
    const double perPixel = raysPerPixel(reference.get(), scene, shape, kSample, kDefaultSettings);
    const double total = perPixel * double(area.width()) * area.height();
    if (total <= kManyRays) return false;
    TraceSettings fixed = kDefaultSettings;
    fixed.maxDepth = 5;
    fixed.minWeight = 0.0;
    fixed.tolerance = 0.0;
    const double fixedPerPixel = raysPerPixel(reference.get(), scene, shape, kSample, fixed);
    char text[400];
    std::snprintf(text, sizeof text,
                  "at the defaults this render may trace up to %.2g rays (%.0f a pixel on %dx%d of them, traced "
                  "with the CPU reference, which goes deeper than the GPU): light in materials with ks + kt > 1 "
                  "is followed until it saturates. A fixed tree, --depth 5 --min-weight 0 (POV-Ray's settings), "
                  "traces about %.0fx fewer rays, if its error is acceptable",
                  total, perPixel, std::min(kSample, area.width()), std::min(kSample, area.height()),
                  perPixel / std::max(1.0, fixedPerPixel));
    out.push_back(aboutFile(path, text));
    return true;
}

}  // namespace

std::vector<Diagnostic> sceneWarnings(const Scene& scene, const std::string& path, RenderShape shape) {
    std::vector<Diagnostic> out;
    const std::size_t behind = warnAboutLines(scene, path, out);
    warnAboutEmptyView(scene, path, behind, out);
    warnAboutDarkness(scene, path, out);
    // The amplifying warning names the cheaper tree; the size's, a cheaper
    // preview. Where both apply, the tree is the cause.
    SampleReference reference(scene);
    if (!warnAboutAmplifying(scene, shape, path, reference, out)) warnAboutCost(scene, shape, path, reference, out);
    return inLineOrder(std::move(out));
}

std::vector<Diagnostic> partialSceneWarnings(const Scene& scene, const std::string& path) {
    std::vector<Diagnostic> out;
    warnAboutLines(scene, path, out);
    return inLineOrder(std::move(out));
}

Scene sceneOrErrors(ParseOutcome outcome, const std::string& path, bool withWarnings) {
    if (!outcome.error) return std::move(outcome.scene);
    if (!withWarnings) throw std::move(*outcome.error);
    throw outcome.error->withWarnings(partialSceneWarnings(outcome.scene, path));
}

SceneReport checkScene(const Scene& scene, const std::string& path) {
    SceneReport r;
    r.spheres = scene.spheres.size();
    r.ellipsoids = scene.ellipsoidCount();
    r.trueSpheres = r.spheres - r.ellipsoids;
    r.lights = scene.lights.size();
    r.materials = scene.materials.size();
    r.warnings = sceneWarnings(scene, path, {scene.imageSize, scene.supersample});
    r.amplifying = scene.anyAmplifying();
    Aabb box;
    for (const Sphere& s : scene.spheres) {
        const Material& m = scene.materials[s.material];
        r.reflective += m.reflects();
        r.refractive += m.refracts();
        box.grow(sphereBounds(s));
    }
    if (!scene.spheres.empty()) {
        r.lower = box.lower;
        r.upper = box.upper;
    }
    return r;
}

std::string SceneReport::text(const Scene& scene) const {
    std::ostringstream s;
    s << scene.name << ": " << scene.imageSize << "x" << scene.imageSize << " pixels, view half-width "
      << scene.halfWidth << ", supersample " << scene.supersample << "\n"
      << "  spheres     " << spheres << " (" << trueSpheres << " true spheres, " << ellipsoids << " ellipsoids)\n"
      << "  lights      " << lights << "\n"
      << "  materials   " << materials << "; spheres reflecting " << reflective << ", refracting " << refractive
      << (amplifying ? "; amplifying (ks + kt > 1: the ray tree gains weight with depth)" : "") << "\n"
      << "  bounds      " << vec(lower) << " to " << vec(upper) << "\n"
      << "  warnings    " << warnings.size() << "\n";
    return s.str();
}

std::string SceneReport::json(const Scene& scene) const {
    std::ostringstream s;
    s.precision(17);
    s << "{\"scene\": " << jsonString(scene.name) << ", \"size\": " << scene.imageSize
      << ", \"half_width\": " << scene.halfWidth << ", \"supersample\": " << scene.supersample
      << ", \"spheres\": " << spheres << ", \"true_spheres\": " << trueSpheres << ", \"ellipsoids\": " << ellipsoids
      << ", \"lights\": " << lights << ", \"materials\": " << materials << ", \"reflective_spheres\": " << reflective
      << ", \"refractive_spheres\": " << refractive << ", \"amplifying\": " << (amplifying ? "true" : "false")
      << ", \"bounds\": {\"lower\": [" << lower.x << ", " << lower.y << ", " << lower.z << "], \"upper\": ["
      << upper.x << ", " << upper.y << ", " << upper.z << "]}, \"errors\": [], \"errors_not_shown\": 0, \"warnings\": "
      << diagnosticsJson(warnings) << "}";
    return s.str();
}

std::string diagnosticsJson(const std::vector<Diagnostic>& diagnostics) {
    std::string out = "[";
    for (const Diagnostic& d : diagnostics) {
        const bool placed = d.location.line > 0;  // else about the whole file
        out += (out.size() > 1 ? ", " : "") + std::string("{\"file\": ") + jsonString(d.location.file) +
               ", \"line\": " + (placed ? std::to_string(d.location.line) : "null") +
               ", \"column\": " + (placed ? std::to_string(d.location.column) : "null") +
               ", \"message\": " + jsonString(d.message) + "}";
    }
    return out + "]";
}

std::string errorsJson(const std::string& sceneName, const ParseError& errors) {
    return "{\"scene\": " + jsonString(sceneName) + ", \"errors\": " + diagnosticsJson(errors.diagnostics()) +
           ", \"errors_not_shown\": " + std::to_string(errors.notShown()) +
           ", \"warnings\": " + diagnosticsJson(errors.warnings()) + "}";
}

}  // namespace snell
