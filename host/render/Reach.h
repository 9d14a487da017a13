// The light a ray can still bring, bounded by where it starts rather than by
// one number for the scene (render/Truncation.h, RadianceBound's R).
//
// A ray that leaves sphere i's surface outwards (a reflection off its
// outside, a refraction out of it) can never meet i again, a sphere being
// convex; and where i's surface lies inside no other sphere it meets the
// others from outside or nothing. A ray refracted into a true sphere k that
// no other surface enters (`hollow`) meets k's inside only, at the angle it
// came in at (every chord meets a sphere's surface at one angle), so it is
// never totally reflected inside: each inner hit passes ks back in and kt
// out, and sees no light outside k, whose segment leaves k (SPEC §4.3:
// binary shadows, the hit sphere's own surface included).
//
// So with L_k the most light a hit on k returns (I_a·kd + Σ_j I_j·(kd + ks),
// as for R) and L'_k that with the lights inside k only (a hit from inside
// sees no other), the light of a ray into hollow k is at most
// I_k = (L'_k + kt_k·O_k) / (1 − ks_k), and of a ray leaving i outwards at most
//     O_i = max(B, max over k ≠ i of L_k + ks_k·O_k + kt_k·max(I_k, O_k))
// (a refraction into k, or a total reflection off it that leaves outwards).
// Any other sphere k has a J_k for a ray inside it, which meets k from
// inside (L'_k + ks_k·J_k + kt_k·max(O_k, J_k)) or a sphere whose surface
// may lie in k, from either side; a ray leaving i whose surface may lie
// inside k may also meet k from inside. The least such O, J (per channel)
// is finite wherever every path through distinct spheres loses light: two
// glass spheres of ks + kt = 1 facing each other keep it, one beside a
// mirror of ks = 0.9 does not. It is found by iteration and checked: a
// vector that the map does not raise bounds the least one. Every bound is
// at most R; where the iteration does not settle within its work, R.
//
// A ray from an eye inside a hollow sphere starts inside it at any angle, so
// for such an eye the inward bounds do not hold (inwardHolds).
#pragma once

#include <vector>

#include "render/Truncation.h"
#include "scene/Scene.h"

namespace snell {

struct ReachBound {
    std::vector<glm::dvec3> outward;  // per sphere: a ray leaving its surface outwards (O)
    std::vector<glm::dvec3> inward;   // per sphere: a ray starting into it (I where hollow, else J)
    std::vector<bool> hollow;         // per sphere: a true sphere no other surface enters, that refracts
};
ReachBound reachBound(const Scene& scene, const RadianceBound& radiance);

// Whether `inward` holds for rays from `eye`: no hollow sphere holds it.
bool inwardHolds(const Scene& scene, const std::vector<bool>& hollow, const glm::dvec3& eye);

}  // namespace snell
