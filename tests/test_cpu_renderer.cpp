// The CPU reference renderer (reference/CpuRenderer.h), the oracle of every
// other test: pixels computed by hand from SPEC §4's shading (diffuse,
// ambient, background, specular and reflection, shadows), and the same image
// whatever the threads and whichever path (render or renderPixel) gives it.
#include <gtest/gtest.h>

#include <string>

#include "reference/CpuRenderer.h"
#include "render/RenderRequest.h"
#include "scene/Parser.h"

namespace {

using glm::dvec3;

snell::Scene parse(const std::string& text) { return snell::parseScene(text, "t.scn"); }

void expectNear(dvec3 a, dvec3 b, double tolerance = 1e-12) {
    EXPECT_NEAR(a.x, b.x, tolerance) << "x";
    EXPECT_NEAR(a.y, b.y, tolerance) << "y";
    EXPECT_NEAR(a.z, b.z, tolerance) << "z";
}

snell::RenderRequest requestFor(const snell::Scene& s) {
    snell::RenderRequest r;
    r.camera = snell::Camera::fromSpec(s.imageSize, s.halfWidth);
    r.width = r.height = s.imageSize;
    r.supersample = s.supersample;
    r.trace = snell::kReferenceSettings;
    r.threads = 1;
    return r;
}

TEST(CpuRenderer, DiffusePixelByHand) {
    // Hit at (0,0,-2), N = (0,0,1), L = normalize((0,0,10) - (0,0,-2)) = (0,0,1):
    // C = kd (N.L) = 0.5.
    const snell::Scene s = parse("view 1 1\nmove 0 0 -3\nmaterial 0.5 0.5 0.5 0 0 0 1\nsphere\n"
                                 "light 1 1 1 0 0 10\nambient 0 0 0\n");
    const snell::CpuRenderer renderer(s);
    const snell::RenderRequest req = requestFor(s);
    const snell::Image image = renderer.render(req);
    ASSERT_EQ(image.width, 1);
    ASSERT_EQ(image.height, 1);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(image.pixel(0, 0)[k], 0.5f, 1e-6f);
    snell::RayCounts counts;
    const dvec3 c = renderer.renderPixel(req, 0, 0, counts).colour;
    expectNear(c, dvec3(0.5), 1e-12);
    EXPECT_EQ(counts.primary, 1u);
    EXPECT_EQ(counts.shadow, 1u);
}

TEST(CpuRenderer, ObliqueLightAmbientAndBackground) {
    // Light at (3,0,-2): L from (0,0,-2) is (1,0,0), N.L = 0: only ambient.
    // A second light at (0,4,1): L = normalize(0,4,3) = (0,0.8,0.6), N.L = 0.6.
    const snell::Scene s = parse("view 3 1\nbackground 0.1 0.2 0.3\nambient 0.2 0.4 0.6\n"
                                 "move 0 0 -3\nmaterial 0.5 0.25 1 0 0 0 1\nsphere\n"
                                 "light 1 1 1 3 0 -2\nlight 1 0.5 2 0 4 1\n");
    const snell::CpuRenderer renderer(s);
    const snell::RenderRequest req = requestFor(s);
    const snell::Image image = renderer.render(req);
    // Centre pixel (1,1): ray straight down -z.
    const dvec3 kd(0.5, 0.25, 1.0);
    const dvec3 expected = dvec3(0.2, 0.4, 0.6) * kd + dvec3(1, 0.5, 2) * kd * 0.6;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(image.pixel(1, 1)[k], expected[k], 1e-6) << k;
    // Corner pixel (0,0): direction normalize(-2/3, 2/3, -1) misses: background.
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(image.pixel(0, 0)[k], 0.1f * (k + 1), 1e-7f) << k;
}

TEST(CpuRenderer, SpecularAndReflectionByHand) {
    // R = 2(N.L)N - L = (0,0,1) = V: specular ks (R.V)^p = 0.25. The reflected
    // ray (0,0,1) leaves the scene: + ks * background = 0.25 * 0.2.
    const snell::Scene s = parse("view 1 1\nbackground 0.2 0.2 0.2\nmove 0 0 -3\n"
                                 "material 0.5 0.5 0.5 0.25 0.25 0.25 10\nsphere\nlight 1 1 1 0 0 10\n");
    const snell::CpuRenderer renderer(s);
    const snell::Image image = renderer.render(requestFor(s));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(image.pixel(0, 0)[k], 0.5 + 0.25 + 0.25 * 0.2, 1e-6);
}

TEST(CpuRenderer, ShadowFromSphereBehindTheEye) {
    // A sphere at z = 5 is behind the eye (not seen) but blocks the light.
    const snell::Scene s = parse("view 1 1\nbackground 0.3 0.3 0.3\nambient 0.1 0.1 0.1\n"
                                 "group\nmove 0 0 -3\nmaterial 0.5 0.5 0.5 0 0 0 1\nsphere\ngroupend\n"
                                 "move 0 0 5\nsphere\nlight 1 1 1 0 0 10\n");
    const snell::CpuRenderer renderer(s);
    const snell::Image image = renderer.render(requestFor(s));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(image.pixel(0, 0)[k], 0.1 * 0.5, 1e-7);
}

// Glass, mirrors and supersampling: the threads share the rows, and each
// pixel is the one renderPixel gives alone; the ray counts add up.
TEST(CpuRenderer, ThreadsAndSinglePixelsGiveTheSameImage) {
    const snell::Scene s = parse("view 12 1\nsupersample 2\nbackground 0.1 0.2 0.3\n"
                                 "material 0.1 0.1 0.1 0.5 0.5 0.5 50\nrefraction 1 1 1 1.5\n"
                                 "group\nmove -0.4 0 -3\nscale 0.6 0.6 0.6\nsphere\ngroupend\n"
                                 "material 0.4 0.2 0.1 0.5 0.5 0.5 10\nmove 0.6 0.2 -3.5\nscale 0.7 0.7 0.7\nsphere\n"
                                 "light 1 1 1 3 4 3\nlight 0.5 0.5 0.5 -3 2 1\n");
    const snell::CpuRenderer renderer(s);
    snell::RenderRequest one = requestFor(s);
    snell::RayCounts oneCounts, manyCounts;
    const snell::Image single = renderer.render(one, &oneCounts);
    snell::RenderRequest many = one;
    many.threads = 4;
    const snell::Image threaded = renderer.render(many, &manyCounts);
    EXPECT_EQ(single.rgb, threaded.rgb);
    EXPECT_EQ(oneCounts.total(), manyCounts.total());
    EXPECT_EQ(oneCounts.primary, std::uint64_t(12 * 12 * 4));
    EXPECT_GT(oneCounts.refracted, 0u);
    EXPECT_GT(oneCounts.reflected, 0u);
    snell::RayCounts pixelCounts;
    for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 12; ++x) {
            const dvec3 c = renderer.renderPixel(one, x, y, pixelCounts).colour;
            for (int k = 0; k < 3; ++k) EXPECT_EQ(float(c[k]), single.pixel(x, y)[k]) << x << ", " << y;
        }
    EXPECT_EQ(pixelCounts.total(), oneCounts.total());
}

}  // namespace
