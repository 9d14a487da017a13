// Transforms (SPEC §2), ray–sphere intersection and Snell's law (SPEC §4–5).
// The CPU renderer's pixels by hand are in test_cpu_renderer.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "reference/Intersect.h"
#include "render/Margins.h"
#include "scene/Parser.h"
#include "scene/Transform.h"

namespace {

using glm::dvec3;
using snell::kNoHit;
using snell::Ray;
using snell::StartsOn;

snell::Scene parse(const std::string& text) { return snell::parseScene(text, "t.scn"); }

dvec3 apply(const glm::dmat4& m, dvec3 p) { return dvec3(m * glm::dvec4(p, 1.0)); }

void expectNear(dvec3 a, dvec3 b, double tolerance = 1e-12) {
    EXPECT_NEAR(a.x, b.x, tolerance) << "x";
    EXPECT_NEAR(a.y, b.y, tolerance) << "y";
    EXPECT_NEAR(a.z, b.z, tolerance) << "z";
}

// ---------------------------------------------------------------- transforms

TEST(Transform, SpecExampleMoveThenScale) {
    // SPEC §2: move 1 0 0 / scale 2 2 2 / sphere -> radius 2 centred at (1,0,0).
    const snell::Scene s = parse("view 10 1\nmove 1 0 0\nscale 2 2 2\nsphere\n");
    ASSERT_EQ(s.spheres.size(), 1u);
    const snell::Sphere& sp = s.spheres[0];
    EXPECT_TRUE(sp.isTrueSphere);
    expectNear(sp.centre, {1, 0, 0});
    EXPECT_NEAR(sp.radius, 2.0, 1e-12);
    expectNear(apply(sp.worldFromObject, {1, 0, 0}), {3, 0, 0});
    expectNear(apply(sp.worldFromObject, {0, -1, 0}), {1, -2, 0});
}

TEST(Transform, ScaleThenMoveScalesTheMove) {
    const snell::Scene s = parse("view 10 1\nscale 2 2 2\nmove 1 0 0\nsphere\n");
    ASSERT_EQ(s.spheres.size(), 1u);
    EXPECT_TRUE(s.spheres[0].isTrueSphere);
    expectNear(s.spheres[0].centre, {2, 0, 0});
    EXPECT_NEAR(s.spheres[0].radius, 2.0, 1e-12);
}

TEST(Transform, RotationIsCounterClockwiseLikeGlRotate) {
    const snell::Scene s = parse("view 10 1\nrotate 90 0 0 1\nsphere\n");
    expectNear(apply(s.spheres[0].worldFromObject, {1, 0, 0}), {0, 1, 0});
    expectNear(apply(s.spheres[0].worldFromObject, {0, 1, 0}), {-1, 0, 0});
    // Right-handed about every axis: x->y about z, y->z about x, z->x about y.
    expectNear(snell::rotationMatrix(90, {1, 0, 0}) * dvec3(0, 1, 0), {0, 0, 1});
    expectNear(snell::rotationMatrix(90, {0, 1, 0}) * dvec3(0, 0, 1), {1, 0, 0});
    expectNear(snell::rotationMatrix(-90, {0, 0, 1}) * dvec3(1, 0, 0), {0, -1, 0});
    // A general angle, and an axis that is not unit length.
    const double c = std::cos(30.0 * std::numbers::pi / 180.0), sn = std::sin(30.0 * std::numbers::pi / 180.0);
    expectNear(snell::rotationMatrix(30, {0, 0, 5}) * dvec3(1, 0, 0), {c, sn, 0}, 1e-15);
    // 120 degrees about (1,1,1) cycles the axes x -> y -> z.
    expectNear(snell::rotationMatrix(120, {1, 1, 1}) * dvec3(1, 0, 0), {0, 1, 0}, 1e-15);
    // Axis pointing away from the viewer reverses the sense.
    expectNear(snell::rotationMatrix(90, {0, 0, -1}) * dvec3(1, 0, 0), {0, -1, 0});
}

TEST(Transform, RotationMatrixIsOrthonormal) {
    const glm::dmat3 r = snell::rotationMatrix(37.5, {0.3, -2, 1.1});
    const glm::dmat3 rtr = glm::transpose(r) * r;
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(rtr[c][k], c == k ? 1.0 : 0.0, 1e-15);
    EXPECT_NEAR(glm::determinant(r), 1.0, 1e-15);
    // The axis is fixed.
    expectNear(r * dvec3(0.3, -2, 1.1), {0.3, -2, 1.1}, 1e-14);
}

TEST(Transform, ObjectFromWorldIsTheInverse) {
    const snell::Scene s = parse("view 10 1\nscale 1 2 3\nrotate 33 1 2 3\nmove 4 -5 6\nscale -2 0.5 7\n"
                                 "rotate -71 0 1 0\nmove 0.1 0.2 0.3\nsphere\n");
    const snell::Sphere& sp = s.spheres[0];
    const glm::dmat4 product = sp.objectFromWorld * sp.worldFromObject;
    const glm::dmat4 other = sp.worldFromObject * sp.objectFromWorld;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            EXPECT_NEAR(product[c][r], c == r ? 1.0 : 0.0, 1e-12) << c << "," << r;
            EXPECT_NEAR(other[c][r], c == r ? 1.0 : 0.0, 1e-12) << c << "," << r;
        }
    // And via the Transform class directly.
    snell::Transform t;
    t.translate({1, 2, 3});
    t.rotate(45, {1, 0, 0});
    t.scale({2, 4, 8});
    EXPECT_TRUE(t.invertible());
    const dvec3 p(0.3, -0.7, 0.9);
    expectNear(apply(t.objectFromWorld(), apply(t.worldFromObject(), p)), p);
}

TEST(Transform, DegenerateAfterUnderflowIsNotInvertible) {
    snell::Transform t;
    t.scale(dvec3(1e-200));
    t.scale(dvec3(1e-200));
    EXPECT_FALSE(t.invertible());
}

TEST(Transform, ClassifyUniformScaleAndRotationAsTrueSphere) {
    const snell::Scene s = parse("view 10 1\nmove 1 2 3\nrotate 37 1 1 0\nscale 2.5 2.5 2.5\nrotate 11 0 1 1\nsphere\n");
    const snell::Sphere& sp = s.spheres[0];
    EXPECT_TRUE(sp.isTrueSphere);
    EXPECT_NEAR(sp.radius, 2.5, 1e-12);
    expectNear(sp.centre, {1, 2, 3});
    // Every surface point is at the radius from the centre.
    for (dvec3 p : {dvec3(1, 0, 0), dvec3(0, 1, 0), glm::normalize(dvec3(1, -2, 3))})
        EXPECT_NEAR(glm::length(apply(sp.worldFromObject, p) - sp.centre), 2.5, 1e-12);
}

TEST(Transform, ClassifyNonUniformScaleAsEllipsoid) {
    const snell::Scene s = parse("view 10 1\nscale 1 2 1\nsphere\nscale 1 0.5 1\nrotate 45 0 0 1\nscale 3 1 1\nsphere\n");
    ASSERT_EQ(s.spheres.size(), 2u);
    EXPECT_FALSE(s.spheres[0].isTrueSphere);
    EXPECT_FALSE(s.spheres[1].isTrueSphere);
    EXPECT_EQ(s.ellipsoidCount(), 2u);
    // The ellipsoid's radius bounds it: at least the longest semi-axis.
    EXPECT_GE(s.spheres[0].radius, 2.0);
    EXPECT_GE(s.spheres[1].radius, 3.0);
}

TEST(Transform, ClassifyNegativeUniformScaleAsTrueSphere) {
    const snell::Scene s = parse("view 10 1\nscale -1 -1 -1\nsphere\nscale -1 1 1\nsphere\n");
    ASSERT_EQ(s.spheres.size(), 2u);
    EXPECT_TRUE(s.spheres[0].isTrueSphere);
    EXPECT_NEAR(s.spheres[0].radius, 1.0, 1e-15);
    expectNear(s.spheres[0].centre, {0, 0, 0});
    // (-1,-1,-1) then (-1,1,1): a mirror, still a sphere of radius 1.
    EXPECT_TRUE(s.spheres[1].isTrueSphere);
    EXPECT_NEAR(s.spheres[1].radius, 1.0, 1e-15);
}

// ---------------------------------------------------------------- intersection

TEST(Intersect, FromOutside) {
    const Ray ray{{0, 0, 5}, {0, 0, -1}};
    EXPECT_DOUBLE_EQ(snell::intersectSphere({0, 0, 0}, 1.0, ray, StartsOn::Elsewhere), 4.0);
    // Off-centre sphere of radius 2.
    const Ray r2{{1, 2, 10}, {0, 0, -1}};
    EXPECT_DOUBLE_EQ(snell::intersectSphere({1, 2, 3}, 2.0, r2, StartsOn::Elsewhere), 5.0);
    // Oblique: from (0,0,5) towards (0.6, 0, 0.8) on the unit sphere... the
    // ray through (3,0,-4)/5 direction hits at t where |o + t d| = 1.
    const dvec3 d = glm::normalize(dvec3(0.6, 0, 0.8 - 5.0));
    const double t = snell::intersectSphere({0, 0, 0}, 1.0, {{0, 0, 5}, d}, StartsOn::Elsewhere);
    EXPECT_NEAR(t, glm::length(dvec3(0.6, 0, 0.8 - 5.0)), 1e-12);
}

TEST(Intersect, FromInside) {
    const Ray ray{{0, 0, 0}, {0, 0, -1}};
    EXPECT_DOUBLE_EQ(snell::intersectSphere({0, 0, 0}, 1.0, ray, StartsOn::Elsewhere), 1.0);
    const Ray off{{0, 0, 0.5}, {0, 0, 1}};
    EXPECT_DOUBLE_EQ(snell::intersectSphere({0, 0, 0}, 1.0, off, StartsOn::Elsewhere), 0.5);
}

TEST(Intersect, Miss) {
    EXPECT_EQ(snell::intersectSphere({0, 0, 0}, 1.0, {{0, 2, 5}, {0, 0, -1}}, StartsOn::Elsewhere), kNoHit);
    // Sphere behind the ray's origin: only t > 0 counts.
    EXPECT_EQ(snell::intersectSphere({0, 0, 0}, 1.0, {{0, 0, 5}, {0, 0, 1}}, StartsOn::Elsewhere), kNoHit);
    EXPECT_TRUE(std::isinf(snell::intersectSphere({0, 0, 0}, 1.0, {{1.5, 0, 5}, {0, 0, -1}}, StartsOn::Elsewhere)));
}

TEST(Intersect, NearlyTangent) {
    const double y = 1.0 - 1e-9;
    const double t = snell::intersectSphere({0, 0, 0}, 1.0, {{0, y, 5}, {0, 0, -1}}, StartsOn::Elsewhere);
    EXPECT_NEAR(t, 5.0 - std::sqrt(1.0 - y * y), 1e-9);
    EXPECT_LT(t, 5.0);
    EXPECT_EQ(snell::intersectSphere({0, 0, 0}, 1.0, {{0, 1.0 + 1e-9, 5}, {0, 0, -1}}, StartsOn::Elsewhere),
              kNoHit);
}

TEST(Intersect, TinySphereFarAway) {
    // SPEC §5 scales: radius 1e-4 at x = 1e6; exact answer 1 - 1e-4.
    const Ray ray{{1e6, 0, 1}, {0, 0, -1}};
    EXPECT_NEAR(snell::intersectSphere({1e6, 0, 0}, 1e-4, ray, StartsOn::Elsewhere), 1.0 - 1e-4, 1e-13);
}

TEST(Intersect, StartsOnLeavingNeverHits) {
    // Leaving a convex sphere from its surface: it cannot be hit again.
    EXPECT_EQ(snell::intersectSphere({0, 0, 0}, 1.0, {{0, 0, 1}, {0, 0, 1}}, StartsOn::Leaving), kNoHit);
    EXPECT_EQ(snell::intersectSphere({0, 0, 0}, 1.0, {{0, 0, 1}, {0, 0, -1}}, StartsOn::Leaving), kNoHit);
    EXPECT_EQ(snell::intersectUnitSphere({0, 0, 1}, {0, 0, -3}, StartsOn::Leaving), kNoHit);
}

TEST(Intersect, StartsOnEnteringGivesTheChord) {
    EXPECT_DOUBLE_EQ(snell::intersectSphere({0, 0, 0}, 1.0, {{0, 0, 1}, {0, 0, -1}}, StartsOn::Entering), 2.0);
    // Oblique chord from (1,0,0) towards (0,1,0): length sqrt(2).
    const Ray ray{{1, 0, 0}, glm::normalize(dvec3(-1, 1, 0))};
    const double t = snell::intersectSphere({0, 0, 0}, 1.0, ray, StartsOn::Entering);
    EXPECT_NEAR(t, std::sqrt(2.0), 1e-15);
    expectNear(ray.origin + t * ray.direction, {0, 1, 0}, 1e-15);
    // A radius-3 sphere elsewhere: the chord through the centre is the diameter.
    EXPECT_NEAR(snell::intersectSphere({5, 5, 5}, 3.0, {{8, 5, 5}, {-1, 0, 0}}, StartsOn::Entering), 6.0, 1e-14);
    // "Entering" with a direction that points outwards gives nothing.
    EXPECT_EQ(snell::intersectSphere({0, 0, 0}, 1.0, {{0, 0, 1}, {0, 0, 1}}, StartsOn::Entering), kNoHit);
}

TEST(Intersect, UnitSphereWithNonUnitDirection) {
    // t is in units of d: o + t d = (0,0,1) at t = 2 for d = (0,0,-2).
    EXPECT_DOUBLE_EQ(snell::intersectUnitSphere({0, 0, 5}, {0, 0, -2}, StartsOn::Elsewhere), 2.0);
    EXPECT_DOUBLE_EQ(snell::intersectUnitSphere({0, 0, 0}, {0, 0.5, 0}, StartsOn::Elsewhere), 2.0);
    EXPECT_DOUBLE_EQ(snell::intersectUnitSphere({0, 0, 1}, {0, 0, -2}, StartsOn::Entering), 1.0);
    EXPECT_EQ(snell::intersectUnitSphere({0, 3, 5}, {0, 0, -2}, StartsOn::Elsewhere), kNoHit);
    // An ellipsoid through its object frame gives the world t: scale 1 2 1,
    // world ray from (0,10,0) down -y hits y = 2 at t = 8.
    const snell::Scene s = parse("view 10 1\nscale 1 2 1\nsphere\n");
    const snell::Sphere& sp = s.spheres[0];
    const dvec3 o = apply(sp.objectFromWorld, {0, 10, 0});
    const dvec3 d = glm::dmat3(sp.objectFromWorld) * dvec3(0, -1, 0);
    EXPECT_NEAR(snell::intersectUnitSphere(o, d, StartsOn::Elsewhere), 8.0, 1e-14);
}

// ---------------------------------------------------------------- refraction

TEST(Refraction, SnellsLawAt45Degrees) {
    const dvec3 n(0, 1, 0);
    const double s45 = std::sqrt(0.5);
    const dvec3 d(s45, -s45, 0);
    dvec3 t;
    ASSERT_TRUE(snell::refractDirection(d, n, 1.0 / 1.5, t));
    EXPECT_NEAR(glm::length(t), 1.0, 1e-15);
    EXPECT_LT(t.y, 0.0);          // continues through the surface
    EXPECT_NEAR(t.z, 0.0, 1e-15);  // stays in the plane of incidence
    const double sinT = glm::length(glm::cross(t, -n));
    EXPECT_NEAR(sinT, s45 / 1.5, 1e-15);
    EXPECT_NEAR(t.x, s45 / 1.5, 1e-15);  // bends towards the normal
    EXPECT_NEAR(std::asin(t.x) * 180.0 / std::numbers::pi, 28.1255057, 1e-6);
}

TEST(Refraction, NormalIncidencePassesStraight) {
    dvec3 t;
    ASSERT_TRUE(snell::refractDirection({0, 0, -1}, {0, 0, 1}, 1.0 / 1.5, t));
    expectNear(t, {0, 0, -1}, 1e-15);
    ASSERT_TRUE(snell::refractDirection({0, 0, -1}, {0, 0, 1}, 1.5, t));
    expectNear(t, {0, 0, -1}, 1e-15);
}

TEST(Refraction, TotalInternalReflection) {
    const dvec3 n(0, 1, 0);
    const double a60 = 60.0 * std::numbers::pi / 180.0;
    const dvec3 d(std::sin(a60), -std::cos(a60), 0);
    dvec3 t(7.0);
    EXPECT_FALSE(snell::refractDirection(d, n, 1.5, t));  // 1.5 sin 60 = 1.30 > 1
    // Below the critical angle (41.8 degrees) it refracts, away from the normal.
    const double a40 = 40.0 * std::numbers::pi / 180.0;
    ASSERT_TRUE(snell::refractDirection({std::sin(a40), -std::cos(a40), 0}, n, 1.5, t));
    EXPECT_NEAR(t.x, 1.5 * std::sin(a40), 1e-14);
    EXPECT_LT(t.y, 0.0);
}

TEST(Refraction, ReflectDirectionByHand) {
    const double s = std::sqrt(0.5);
    expectNear(snell::reflectDirection({s, -s, 0}, {0, 1, 0}), {s, s, 0}, 1e-15);
    expectNear(snell::reflectDirection({0, 0, -1}, {0, 0, 1}), {0, 0, 1});
    expectNear(snell::reflectDirection({1, 0, 0}, glm::normalize(dvec3(-1, 1, 0))), {0, 1, 0}, 1e-15);
    // Grazing: tangent direction is unchanged.
    expectNear(snell::reflectDirection({1, 0, 0}, {0, 1, 0}), {1, 0, 0});
}

// ---------------------------------------------------------------- margins

// The most Phong's factor max(0, c)^p moves for c within delta of rv (SPEC
// §4.3): it is monotone in c, so at one end of the interval.
double specularSpread(double rv, double p, double delta) {
    auto factor = [p](double c) { return c > 0.0 ? std::pow(std::min(c, 1.0), p) : 0.0; };
    const double at = factor(rv);
    return std::max(factor(rv + delta) - at, at - factor(rv - delta));
}

TEST(Margins, SpecularOffCoversTheWholeInterval) {
    // Where p·δ/rv is not small the slope p·rv^(p−1)·δ understates how far
    // the factor may rise (it is convex): a mirror's exponent of 1e5 with R·V
    // tilted by 1e-4 may light a highlight the computed ray misses.
    const double exponents[] = {0.0, 0.3, 1.0, 3.0, 100.0, 1e5};
    const double deltas[] = {1e-9, 1e-6, 1e-4, 1e-2};
    const double cosines[] = {-1e-3, -1e-7, 1e-8, 1e-3, 0.3, 0.9, 0.9999, 1.0 - 1e-6};
    for (double p : exponents)
        for (double delta : deltas)
            for (double rv : cosines) {
                const double factor = rv > 0.0 ? std::pow(rv, p) : 0.0;
                const double off = snell::margins::specularOff(rv, p, delta, factor, 0.0);
                EXPECT_GE(off * (1.0 + 1e-12) + 1e-15, specularSpread(rv, p, delta)) << "p " << p << " delta " << delta << " rv " << rv;
                EXPECT_LE(off, 1.0);
            }
    // Where p·δ/rv is small it is the slope, to first order.
    const double rv = 0.9, p = 10.0, delta = 1e-8;
    EXPECT_NEAR(snell::margins::specularOff(rv, p, delta, std::pow(rv, p), 0.0), p * std::pow(rv, p - 1.0) * delta, 1e-14);
}

}  // namespace
