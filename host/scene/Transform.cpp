#include "scene/Transform.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace snell {

glm::dmat3 rotationMatrix(double degrees, dvec3 axis) {
    // Scale before normalising so huge or tiny axes neither overflow nor vanish.
    const double largest = std::max({std::abs(axis.x), std::abs(axis.y), std::abs(axis.z)});
    const dvec3 u = glm::normalize(axis / largest);
    // Exact quarter turns keep exact zeros (rotate 90 gives no 6e-17 residue).
    const double reduced = std::fmod(degrees, 360.0);
    double c, s;
    if (reduced == 0.0) { c = 1.0; s = 0.0; }
    else if (reduced == 90.0 || reduced == -270.0) { c = 0.0; s = 1.0; }
    else if (reduced == 180.0 || reduced == -180.0) { c = -1.0; s = 0.0; }
    else if (reduced == 270.0 || reduced == -90.0) { c = 0.0; s = -1.0; }
    else {
        const double radians = reduced * std::numbers::pi / 180.0;
        c = std::cos(radians);
        s = std::sin(radians);
    }
    const double t = 1.0 - c;
    // Rodrigues' formula, as glRotate documents it (column-major: m[col][row]).
    glm::dmat3 r;
    r[0] = dvec3(t * u.x * u.x + c, t * u.x * u.y + s * u.z, t * u.x * u.z - s * u.y);
    r[1] = dvec3(t * u.x * u.y - s * u.z, t * u.y * u.y + c, t * u.y * u.z + s * u.x);
    r[2] = dvec3(t * u.x * u.z + s * u.y, t * u.y * u.z - s * u.x, t * u.z * u.z + c);
    return r;
}

void Transform::scale(dvec3 s) {
    dmat4 m(1.0), inverse(1.0);
    for (int k = 0; k < 3; ++k) {
        m[k][k] = s[k];
        inverse[k][k] = 1.0 / s[k];
    }
    worldFromObject_ = worldFromObject_ * m;
    objectFromWorld_ = inverse * objectFromWorld_;
}

void Transform::translate(dvec3 t) {
    dmat4 m(1.0), inverse(1.0);
    m[3] = glm::dvec4(t, 1.0);
    inverse[3] = glm::dvec4(-t, 1.0);
    worldFromObject_ = worldFromObject_ * m;
    objectFromWorld_ = inverse * objectFromWorld_;
}

void Transform::rotate(double degrees, dvec3 axis) {
    const glm::dmat3 r = rotationMatrix(degrees, axis);
    worldFromObject_ = worldFromObject_ * dmat4(r);
    objectFromWorld_ = dmat4(glm::transpose(r)) * objectFromWorld_;
}

bool Transform::invertible() const {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(worldFromObject_[c][r]) || !std::isfinite(objectFromWorld_[c][r]))
                return false;
    const double det = glm::determinant(glm::dmat3(worldFromObject_));
    const double inverseDet = glm::determinant(glm::dmat3(objectFromWorld_));
    return std::isnormal(det) && std::isnormal(inverseDet);
}

void classifySphere(Sphere& sphere) {
    const glm::dmat3 a(sphere.worldFromObject);
    const glm::dmat3 gram = glm::transpose(a) * a;
    const double s2 = (gram[0][0] + gram[1][1] + gram[2][2]) / 3.0;
    // A relative deviation of 1e-9 from a similarity moves the surface by at
    // most 1e-9 of the radius: far below float32 resolution.
    const double tolerance = 1e-9 * s2;
    bool similarity = true;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            similarity &= std::abs(gram[c][r] - (c == r ? s2 : 0.0)) <= tolerance;
    sphere.isTrueSphere = similarity;
    sphere.centre = dvec3(sphere.worldFromObject[3]);
    // For an ellipsoid, `radius` bounds it: the Frobenius norm of the linear
    // part is at least its largest singular value (the longest semi-axis).
    sphere.radius = similarity ? std::sqrt(s2)
                               : std::sqrt(glm::dot(a[0], a[0]) + glm::dot(a[1], a[1]) +
                                           glm::dot(a[2], a[2]));
}

}  // namespace snell
