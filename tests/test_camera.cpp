// Cameras: the general look-at camera reproduces SPEC §3's exactly, and the
// preview's orbit camera starts there, orbits about its pivot and comes back.
#include <cmath>

#include <gtest/gtest.h>

#include "preview/OrbitCamera.h"
#include "scene/Parser.h"

namespace {

using snell::dvec3;

void expectSame(const snell::Camera& a, const snell::Camera& b) {
    EXPECT_EQ(a.eye, b.eye);
    EXPECT_EQ(a.forward, b.forward);
    EXPECT_EQ(a.cornerDir, b.cornerDir);
    EXPECT_EQ(a.pixelRight, b.pixelRight);
    EXPECT_EQ(a.pixelDown, b.pixelDown);
}

TEST(Camera, LookAtIsSpecCameraExactly) {
    for (double d : {0.5, 0.3, 1.7}) {
        const snell::Camera spec = snell::Camera::fromSpec(512, d);
        EXPECT_EQ(spec.eye, dvec3(0, 0, 1));
        EXPECT_EQ(spec.cornerDir, dvec3(-d, d, -1));
        EXPECT_EQ(spec.pixelRight, dvec3(2 * d / 512, 0, 0));
        EXPECT_EQ(spec.pixelDown, dvec3(0, -2 * d / 512, 0));
    }
}

TEST(Camera, LookAtFramesTheTarget) {
    const snell::Camera c = snell::Camera::lookAt(dvec3(3, 0, 0), dvec3(0), dvec3(0, 1, 0), 0.5, 100, 100);
    EXPECT_NEAR(glm::length(c.forward - dvec3(-1, 0, 0)), 0.0, 1e-15);
    // The image centre looks at the target.
    EXPECT_NEAR(glm::length(c.direction(50, 50) - dvec3(-1, 0, 0)), 0.0, 1e-12);
    // Up in the image is +y.
    EXPECT_GT(c.direction(50, 0).y, 0.0);
}

snell::Scene sphereAt(double z) {
    return snell::parseScene("view 64 0.5\nmaterial 1 1 1 0 0 0 1\nmove 0 0 " + std::to_string(z) +
                                     "\nsphere\n",
                                 "orbit.scn");
}

TEST(OrbitCamera, StartsAtTheSceneCameraAndPivotsOnTheFirstSurface) {
    const snell::Scene scene = sphereAt(-3);
    const snell::Camera home = snell::Camera::fromSpec(64, 0.5);
    snell::OrbitCamera orbit(scene, home, 0.5);
    expectSame(orbit.camera(64, 64), home);
    // The central ray meets the unit sphere at z = -2: 3 units from the eye.
    EXPECT_NEAR(orbit.pivot().z, -2.0, 1e-12);
}

TEST(OrbitCamera, OrbitKeepsDistanceAndAFullTurnComesBack) {
    const snell::Scene scene = sphereAt(-3);
    const snell::Camera home = snell::Camera::fromSpec(64, 0.5);
    snell::OrbitCamera orbit(scene, home, 0.5);
    orbit.orbitDegrees(90);
    const snell::Camera turned = orbit.camera(64, 64);
    EXPECT_NEAR(glm::length(turned.eye - orbit.pivot()), 3.0, 1e-12);
    EXPECT_NEAR(glm::length(turned.eye - home.eye), 3.0 * std::sqrt(2.0), 1e-12);
    orbit.orbitDegrees(270);
    EXPECT_NEAR(glm::length(orbit.camera(64, 64).eye - home.eye), 0.0, 1e-12);
    orbit.reset();
    expectSame(orbit.camera(64, 64), home);
}

TEST(OrbitCamera, ZoomApproachesAndPanMovesThePivot) {
    const snell::Scene scene = sphereAt(-3);
    snell::OrbitCamera orbit(scene, snell::Camera::fromSpec(64, 0.5), 0.5);
    orbit.zoom(1);
    EXPECT_NEAR(glm::length(orbit.camera(64, 64).eye - orbit.pivot()), 2.7, 1e-12);
    const dvec3 before = orbit.pivot();
    orbit.pan(-64, 0, 64);  // dragging left by a window width moves the view right
    EXPECT_GT(orbit.pivot().x, before.x);
    EXPECT_NEAR(orbit.pivot().y, before.y, 1e-12);
}

TEST(OrbitCamera, PivotWithoutAHitIsTheSceneCentre) {
    const snell::Scene scene = snell::parseScene(
        "view 64 0.5\nmaterial 1 1 1 0 0 0 1\nmove 5 0 -4\nsphere\n", "side.scn");
    EXPECT_NEAR(snell::pivotDistance(scene, dvec3(0, 0, 1), dvec3(0, 0, -1)), 5.0, 1e-12);
    EXPECT_EQ(snell::pivotDistance(snell::Scene{}, dvec3(0, 0, 1), dvec3(0, 0, -1)), 1.0);
}

}  // namespace
