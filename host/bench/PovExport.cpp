#include "bench/PovExport.h"

#include <sstream>

namespace snell {

namespace {

std::string vec(const dvec3& v) {
    std::ostringstream s;
    s.precision(17);
    s << "<" << v.x << ", " << v.y << ", " << v.z << ">";
    return s.str();
}

}  // namespace

std::string toPovRay(const Scene& scene, int depth) {
    std::ostringstream out;
    out.precision(17);
    out << "// " << scene.name << ", written by snell bench\n"
        << "#version 3.7;\n"
        << "global_settings { max_trace_level " << povTraceLevel(depth)
        << " adc_bailout 0 assumed_gamma 1.0 ambient_light rgb "
        << vec(scene.ambient) << " }\n"
        << "background { rgb " << vec(scene.background) << " }\n";
    // SPEC §3: eye (0,0,1) looking down -z at the image plane z = 0, half-width d.
    const double d = scene.halfWidth;
    out << "camera { perspective location <0, 0, 1> direction <0, 0, -1> right <" << 2 * d << ", 0, 0> up <0, "
        << 2 * d << ", 0> }\n";
    for (const Light& l : scene.lights)
        out << "light_source { " << vec(l.position) << " color rgb " << vec(l.colour) << " }\n";
    for (const Sphere& s : scene.spheres) {
        const Material& m = scene.materials[s.material];
        const dmat4& w = s.worldFromObject;
        // POV-Ray's matrix maps row vectors: p' = p · M, so its rows are our columns.
        out << "sphere { 0, 1 matrix <" << w[0][0] << ", " << w[0][1] << ", " << w[0][2] << ", " << w[1][0] << ", "
            << w[1][1] << ", " << w[1][2] << ", " << w[2][0] << ", " << w[2][1] << ", " << w[2][2] << ", " << w[3][0]
            << ", " << w[3][1] << ", " << w[3][2] << ">\n"
            << "  texture { pigment { rgbt <" << m.kd.x << ", " << m.kd.y << ", " << m.kd.z << ", "
            << (m.refracts() ? (m.kt.x + m.kt.y + m.kt.z) / 3.0 : 0.0) << "> }\n"
            << "    finish { ambient 1 diffuse 1 phong " << (m.ks.x + m.ks.y + m.ks.z) / 3.0 << " phong_size " << m.phong
            << " reflection rgb " << vec(m.ks) << " } }\n";
        if (m.refracts()) out << "  interior { ior " << m.eta << " }\n";
        out << "}\n";
    }
    return out.str();
}

bool povModelAgrees(const Scene& scene) {
    for (const Sphere& s : scene.spheres)
        if (scene.materials[s.material].refracts()) return false;
    return true;
}

}  // namespace snell
