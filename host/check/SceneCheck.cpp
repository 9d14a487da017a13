#include "check/SceneCheck.h"

#include <sstream>

#include "bvh/Bvh.h"
#include "common/Json.h"

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

SceneReport checkScene(const Scene& scene, const std::string& path) {
    SceneReport r;
    r.spheres = scene.spheres.size();
    r.ellipsoids = scene.ellipsoidCount();
    r.trueSpheres = r.spheres - r.ellipsoids;
    r.lights = scene.lights.size();
    r.materials = scene.materials.size();
    r.warnings = scene.warnings;
    r.amplifying = scene.anyAmplifying();
    Aabb box;
    const Camera camera = Camera::fromSpec(std::max(1, scene.imageSize), scene.halfWidth);
    for (const Sphere& s : scene.spheres) {
        const Material& m = scene.materials[s.material];
        r.reflective += m.reflects();
        r.refractive += m.refracts();
        const Aabb b = sphereBounds(s);
        box.grow(b);
        const SourceLocation at{path, s.location.line, s.location.column};
        for (std::size_t j = 0; j < scene.lights.size(); ++j) {
            if (inside(s, scene.lights[j].position))
                r.warnings.push_back({at, "light " + std::to_string(j + 1) + " (at " + vec(scene.lights[j].position) +
                                              ") is inside this sphere" +
                                              (m.refracts() ? "" : ", which is opaque: it lights only its inside")});
        }
        // Wholly behind the eye: no primary ray can see it (it may still be reflected).
        if (glm::dot(s.centre - camera.eye, camera.forward) < -s.radius)
            r.warnings.push_back({at, "this sphere is behind the camera (only reflections can show it)"});
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
      << upper.x << ", " << upper.y << ", " << upper.z << "]}, \"warnings\": [";
    for (std::size_t i = 0; i < warnings.size(); ++i)
        s << (i ? ", " : "") << jsonString(warnings[i].format("warning"));
    s << "]}";
    return s.str();
}

}  // namespace snell
