// The scene of SPEC §2 after parsing: everything in world coordinates, double
// precision. Built by parseScene (Parser.h); consumed by the CPU reference and
// by the GPU layout (host/gpu/GpuScene.h).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace snell {

using glm::dmat4;
using glm::dvec3;

// Where something stands in a scene file (SPEC §7: LINE and COL from 1, COL in bytes).
struct SourceLocation {
    std::string file;
    int line = 1;
    int column = 1;
};

inline constexpr double kAirEta = 1.0002926;  // SPEC §2 default refraction index

// A material as SPEC §2 defines it: `material` plus the current `refraction`.
struct Material {
    dvec3 kd{1.0, 1.0, 1.0};
    dvec3 ks{0.0, 0.0, 0.0};
    double phong = 1.0;
    dvec3 kt{0.0, 0.0, 0.0};
    double eta = kAirEta;

    bool reflects() const { return ks.x != 0.0 || ks.y != 0.0 || ks.z != 0.0; }
    bool refracts() const { return kt.x != 0.0 || kt.y != 0.0 || kt.z != 0.0; }
    // What a hit passes on to its children, per channel: ks + kt.
    dvec3 gain() const { return ks + kt; }
    // The largest channel of gain().
    double largestGain() const { return std::max({ks.x + kt.x, ks.y + kt.y, ks.z + kt.z}); }
    // SPEC §4 "amplifying": a ray tree that can gain weight with depth.
    bool amplifies() const { return largestGain() > 1.0; }
    bool operator==(const Material&) const = default;
};

// Hash of a material's values, for deduplicating materials while parsing.
struct MaterialHash {
    std::size_t operator()(const Material& m) const {
        std::size_t h = 0;
        auto mix = [&h](double v) { h = h * 1099511628211ull ^ std::hash<double>()(v); };
        for (int k = 0; k < 3; ++k) {
            mix(m.kd[k]);
            mix(m.ks[k]);
            mix(m.kt[k]);
        }
        mix(m.phong);
        mix(m.eta);
        return h;
    }
};

// A place in the scene's own file (the file name is the scene's).
struct TextPosition {
    int line = 1;
    int column = 1;
};

// The unit sphere at the origin seen through worldFromObject (SPEC §2 `sphere`).
struct Sphere {
    dmat4 worldFromObject{1.0};
    dmat4 objectFromWorld{1.0};
    std::uint32_t material = 0;
    TextPosition location;  // of its `sphere` command

    // A similarity (rotation, uniform scale, translation) maps the unit sphere to
    // a true sphere, stored and intersected as centre + radius; anything else is
    // an ellipsoid. Set by the parser (see classifySphere in Parser.cpp).
    bool isTrueSphere = false;
    dvec3 centre{0.0};
    double radius = 1.0;
};

struct Light {
    dvec3 colour{1.0};
    dvec3 position{0.0};
};

struct Diagnostic {
    SourceLocation location;
    std::string message;
    std::string format(const char* severity) const;
};

struct Scene {
    std::string name;          // file name without directory or extension
    int imageSize = 0;         // view n
    double halfWidth = 0.0;    // view d
    int supersample = 1;       // supersample s
    dvec3 background{0.0};
    dvec3 ambient{0.0};
    std::vector<Sphere> spheres;
    std::vector<Material> materials;  // deduplicated; Sphere::material indexes it
    std::vector<Light> lights;
    std::vector<Diagnostic> warnings;

    std::size_t ellipsoidCount() const;
    std::size_t refractiveSphereCount() const;
    bool anyReflection() const;
    bool anyRefraction() const;
    // Some material has ks + kt > 1 in a channel (SPEC §4 "amplifying").
    bool anyAmplifying() const;
};

// The camera of SPEC §3, or a general one (the preview's): primary rays leave
// `eye` towards cornerDir + x * pixelRight + y * pixelDown, (x, y) in pixels.
struct Camera {
    dvec3 eye{0.0, 0.0, 1.0};
    dvec3 forward{0.0, 0.0, -1.0};  // unit direction through the image centre
    dvec3 cornerDir{0.0};
    dvec3 pixelRight{0.0};
    dvec3 pixelDown{0.0};

    // SPEC §3: eye (0, 0, 1) looking at the origin, y up, the image plane
    // [-halfWidth, halfWidth]² at distance 1.
    static Camera fromSpec(int imageSize, double halfWidth);
    // A general pinhole camera: from `eye` towards `target`, `up` giving the
    // image's vertical, the image plane at unit distance with half-width
    // `halfWidth`. fromSpec is lookAt((0,0,1), (0,0,0), (0,1,0), ...), exactly.
    static Camera lookAt(const dvec3& eye, const dvec3& target, const dvec3& up, double halfWidth, int width,
                         int height);
    dvec3 direction(double x, double y) const {
        return glm::normalize(cornerDir + x * pixelRight + y * pixelDown);
    }
};

}  // namespace snell
