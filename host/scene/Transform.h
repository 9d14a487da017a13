// The parser's current transform M (SPEC §2), kept together with its exact
// inverse: every step is inverted in closed form (1/s, -t, R^T), so the inverse
// is as accurate as the matrix itself rather than a general 4x4 inversion.
#pragma once

#include <glm/glm.hpp>

#include "scene/Scene.h"

namespace snell {

// glRotate's matrix: `degrees` counter-clockwise about `axis` (not necessarily
// unit, not zero) when the axis points at the viewer.
glm::dmat3 rotationMatrix(double degrees, dvec3 axis);

class Transform {
public:
    // M <- M * S, M <- M * T, M <- M * R: OpenGL's right-multiplication.
    void scale(dvec3 s);
    void translate(dvec3 t);
    void rotate(double degrees, dvec3 axis);

    const dmat4& worldFromObject() const { return worldFromObject_; }
    const dmat4& objectFromWorld() const { return objectFromWorld_; }
    // False once repeated scales have under- or overflowed the matrices.
    bool invertible() const;

private:
    dmat4 worldFromObject_{1.0};
    dmat4 objectFromWorld_{1.0};
};

// Decide whether the sphere is a true sphere (similarity transform) and fill
// centre and radius; otherwise it stays an ellipsoid.
void classifySphere(Sphere& sphere);

}  // namespace snell
