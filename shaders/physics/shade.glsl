// 3. One hit's local term (SPEC §4.3): the ambient part, and each light's
// Phong part with a binary shadow. Pure: the caller adds them to the pixel
// and counts the shadow rays.
#ifndef SNELL_PHYSICS_SHADE_GLSL
#define SNELL_PHYSICS_SHADE_GLSL

// Off (a preview inspection switch): no shadow rays, every light is seen.
layout(constant_id = SNELL_SPEC_SHADOWS) const bool SHADOWS = true;

// The ambient part of the local term at hit h.
vec3 ambientTerm(Hit h) { return frame.ambient.rgb * h.kd.rgb; }

// 3. Light j's part of the local Phong term (SPEC §4.3) where the light is
// seen: l, the unit vector towards it, with n·l = nl > 0; v towards the eye.
vec3 lightTerm(uint j, Hit h, rvec3 l, float nl, rvec3 v) {
    float rv = float(dot(2.0 * dot(h.normal, l) * h.normal - l, v));
    float specular = rv > 0.0 ? pow(rv, h.kd.w) : 0.0;
    return lightColour(j) * (h.kd.rgb * nl + h.ks.rgb * specular);
}
// The unit vector l from a point towards light j; returns the distance.
real lightDirection(uint j, rvec3 point, out rvec3 l) {
    l = lightPosition(j) - point;
    real distance = length(l);
    l *= 1.0 / distance;  // one division, not three
    return distance;
}
// The same from hit h, and n·l.
float towardsLight(uint j, Hit h, out rvec3 l, out real distance) {
    distance = lightDirection(j, h.point, l);
    return float(dot(h.normal, l));
}
// How a shadow ray from hit h starts on its sphere: towards N's side it
// enters the sphere only when N = −No (the hit was from inside).
uint shadowStart(Hit h) { return h.fromOutside ? LEAVING : ENTERING; }

// Light j's part of the local term with binary shadows (SPEC §4.3), seen
// from v; castShadowRay: a shadow ray was cast (the surface faces the light).
vec3 shadeLight(uint j, Hit h, rvec3 v, out bool castShadowRay) {
    rvec3 l;
    real distance;
    float nl = towardsLight(j, h, l, distance);
    castShadowRay = false;
    if (!(nl > 0.0)) return vec3(0.0);
    castShadowRay = SHADOWS;
    if (SHADOWS && occluded(h.point, l, distance, h.sphere, shadowStart(h))) return vec3(0.0);
    return lightTerm(j, h, l, nl, v);
}

#endif
