// The light a ray can still bring, bounded by where it starts
// (render/Reach.h): its values on scenes small enough to work out by hand,
// where it falls back to R, and that the bounds it gives a render hold
// against a deep fixed tree.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "reference/CpuRenderer.h"
#include "render/Reach.h"
#include "render/Truncation.h"
#include "scene/Parser.h"

namespace {

snell::Scene parse(const std::string& text) { return snell::parseScene(text, "t.scn"); }

// Glass of ks + kt = 1 (so R is infinite) beside a mirror of ks = 0.9, far
// from the light: L_glass = 1 · 0.1, L'_glass = 0 (no light inside it),
// L_mirror = 1 · 0.9, and no denser medium than the glass. A ray into the
// glass leaves it whole: I = 0.9 O_g / 0.9 = O_g, so a hit on the glass from
// outside returns at most 0.1 + 0.1 O_g + 0.9 O_g, on the mirror 0.9 + 0.9 O_m;
// O_g = 0.9 + 0.9 O_m and O_m = 0.1 + O_g give O_g = 9.9, O_m = 10.
const char* kGlassBesideMirror =
    "view 8 1\nbackground 0.2 0.2 0.2\nlight 1 1 1 0 50 0\n"
    "group\nmaterial 0 0 0 0.1 0.1 0.1 10\nrefraction 0.9 0.9 0.9 1.5\nmove 2 0 -5\nsphere\ngroupend\n"
    "group\nmaterial 0 0 0 0.9 0.9 0.9 10\nmove -2 0 -5\nsphere\ngroupend\n";

TEST(ReachBound, GlassBesideAMirrorIsBoundedWhereRIsNot) {
    const snell::Scene s = parse(kGlassBesideMirror);
    const snell::RadianceBound r = snell::radianceBound(s);
    ASSERT_FALSE(r.finite());
    const snell::ReachBound b = snell::reachBound(s, r);
    EXPECT_TRUE(b.hollow[0]);
    EXPECT_FALSE(b.hollow[1]);  // it does not refract
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(b.outward[0][c], 9.9, 1e-6);
        EXPECT_NEAR(b.outward[1][c], 10.0, 1e-6);
        EXPECT_NEAR(b.inward[0][c], 9.9, 1e-6);
        // Rounded up, never down: a bound.
        EXPECT_GE(b.outward[0][c], 9.9);
        EXPECT_GE(b.outward[1][c], 10.0);
        // No ray goes into the mirror, and one that did would see nothing.
        EXPECT_EQ(b.inward[1][c], 0.0);
    }
}

TEST(ReachBound, TwoGlassSpheresKeepTheirLight) {
    // Light can pass from one to the other and back for ever, losing none.
    const snell::Scene s = parse(
        "view 8 1\nbackground 0.2 0.2 0.2\nlight 1 1 1 0 50 0\nmaterial 0 0 0 0.1 0.1 0.1 10\n"
        "refraction 0.9 0.9 0.9 1.5\ngroup\nmove 2 0 -5\nsphere\ngroupend\ngroup\nmove -2 0 -5\nsphere\ngroupend\n");
    const snell::ReachBound b = snell::reachBound(s, snell::radianceBound(s));
    for (std::size_t i = 0; i < 2; ++i) EXPECT_TRUE(std::isinf(b.outward[i].x));
}

TEST(ReachBound, WhereSurfacesCross) {
    // The glass crosses the mirror: a ray inside it may meet the mirror, and
    // a ray leaving the mirror may start inside the glass. With no light
    // inside, a ray inside the glass returns what leaves it, at most its O
    // (ks + kt = 1: nothing is gained on the way); with one, light may go
    // round inside for ever, and both fall back to R.
    const std::string glass = "group\nmaterial 0 0 0 0.1 0.1 0.1 10\nrefraction 0.9 0.9 0.9 1.5\nmove 0.5 0 -5\nsphere\ngroupend\n";
    const std::string mirror = "group\nmaterial 0 0 0 0.9 0.9 0.9 10\nmove -0.5 0 -5\nsphere\ngroupend\n";
    const snell::Scene dark = parse("view 8 1\nbackground 0.2 0.2 0.2\nlight 1 1 1 0 50 0\n" + glass + mirror);
    const snell::ReachBound b = snell::reachBound(dark, snell::radianceBound(dark));
    EXPECT_FALSE(b.hollow[0]);
    EXPECT_TRUE(std::isfinite(b.outward[1].x));
    EXPECT_TRUE(std::isfinite(b.inward[0].x));
    EXPECT_LE(b.inward[0].x, std::max(b.outward[0].x, b.outward[1].x) * (1.0 + 1e-6));
    const snell::Scene lit = parse("view 8 1\nbackground 0.2 0.2 0.2\nlight 1 1 1 0.8 0 -5\n" + glass + mirror);
    const snell::ReachBound c = snell::reachBound(lit, snell::radianceBound(lit));
    EXPECT_TRUE(std::isinf(c.inward[0].x));
    EXPECT_TRUE(std::isinf(c.outward[1].x));
}

TEST(ReachBound, NeverAboveRAndLightsInsideCount) {
    // R finite (ks + kt = 0.8): every reach is at most R. A light inside the
    // glass lights its inside: L' = 1 · (0.1 + 0.1), not 0.
    const snell::Scene s = parse(
        "view 8 1\nbackground 0.2 0.2 0.2\nlight 1 1 1 2 0 -5\n"
        "group\nmaterial 0.1 0.1 0.1 0.1 0.1 0.1 10\nrefraction 0.7 0.7 0.7 1.5\nmove 2 0 -5\nsphere\ngroupend\n"
        "group\nmaterial 0.8 0.8 0.8 0 0 0 1\nmove -2 0 -5\nsphere\ngroupend\n");
    const snell::RadianceBound r = snell::radianceBound(s);
    ASSERT_TRUE(r.finite());
    const snell::ReachBound b = snell::reachBound(s, r);
    for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_LE(b.outward[i].x, r.radiance.x);
        EXPECT_LE(b.inward[i].x, r.radiance.x);
    }
    // I = (L' + kt O) / (1 − ks) with O the white sphere's light 0.8 at most.
    EXPECT_GE(b.inward[0].x, 0.2 / 0.9);
    EXPECT_NEAR(b.outward[0].x, 0.8, 1e-6);
    EXPECT_NEAR(b.inward[0].x, (0.2 + 0.7 * 0.8) / 0.9, 1e-6);
}

TEST(ReachBound, AnEyeInsideAHollowSphere) {
    // Rays from it start inside at any angle, and may be reflected totally.
    const snell::Scene s = parse(kGlassBesideMirror);
    const snell::ReachBound b = snell::reachBound(s, snell::radianceBound(s));
    EXPECT_TRUE(snell::inwardHolds(s, b.hollow, {0.0, 0.0, 0.0}));
    EXPECT_FALSE(snell::inwardHolds(s, b.hollow, {2.0, 0.3, -5.0}));
    EXPECT_TRUE(snell::inwardHolds(s, b.hollow, {-2.0, 0.3, -5.0}));  // the mirror is not hollow
}

// At the defaults every pixel of the glass beside a mirror states a finite
// bound, which a deep fixed tree (a lower bound of the exact colour, whose
// bound plays no part) does not pass; without the reach, R is infinite and
// no pixel that sees the glass has one.
TEST(ReachBound, RenderedBoundsHoldAgainstADeepTree) {
    const snell::Scene scene = parse(kGlassBesideMirror);
    const snell::CpuRenderer cpu(scene);
    snell::RenderRequest request;
    request.width = request.height = 24;
    request.camera = snell::Camera::fromSpec(24, scene.halfWidth);
    request.threads = 1;
    request.trace = snell::kDefaultSettings;
    request.trace.tolerance = 0.02;  // bounds large enough to be tested
    snell::RenderRequest deep = request;
    deep.trace.tolerance = 0.0;
    deep.trace.minWeight = 1e-10;
    const snell::Image limit = cpu.render(deep);
    int glassPixels = 0;
    for (int y = 0; y < request.height; ++y)
        for (int x = 0; x < request.width; ++x) {
            snell::RayCounts counts;
            const snell::CpuRenderer::Pixel p = cpu.renderPixel(request, x, y, counts);
            ASSERT_FALSE(p.unbounded) << x << ", " << y;
            glassPixels += counts.refracted > 0;
            for (int c = 0; c < 3; ++c) {
                const double lower = std::min(p.colour[c], 1.0);
                const double exact = std::min(double(limit.pixel(x, y)[c]), 1.0);
                EXPECT_LE(exact, lower + p.bound + 1e-6) << x << ", " << y;
            }
        }
    EXPECT_GT(glassPixels, 0);
}

}  // namespace
