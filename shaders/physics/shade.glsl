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
// `error`: how far it may be from the exact term, N·L and R·V being off by
// cosineOff (the normal's and the light direction's uncertainty, and float
// rounding): kd·δ, and (R·V)^p's (margins.glsl, specularOffset) plus pow's own
// error. pow is exp2(y), y = p log2(R·V): Vulkan allows log2 an absolute 2^-21
// near 1, which p multiplies, and exp2 3 + 2|y| ULP (1 ULP <= 2u), which is at
// most 2u x^p + 4u |y| 2^y <= x^p 8u + 9u, as |y| 2^y <= 1/(e ln 2) for y <= 0.
// CpuRenderer::shadeLight's twin.
vec3 lightTerm(uint j, Hit h, rvec3 l, float nl, rvec3 v, float cosineOff, out vec3 error) {
    const float u = 5.9605e-8;  // float's unit roundoff, rounded up
    float rv = float(dot(2.0 * dot(h.normal, l) * h.normal - l, v));
    float p = h.kd.w;
    float specular = rv > 0.0 ? pow(rv, p) : 0.0;
    float specularOff = specularOffset(rv, p, cosineOff, specular, 4.8e-7) + specular * 8.0 * u + 9.0 * u;
    error = lightColour(j) * (h.kd.rgb * cosineOff + h.ks.rgb * specularOff);
    return lightColour(j) * (h.kd.rgb * nl + h.ks.rgb * specular);
}
vec3 lightTerm(uint j, Hit h, rvec3 l, float nl, rvec3 v) {
    vec3 error;
    return lightTerm(j, h, l, nl, v, 0.0, error);
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

// How far a shadow ray from hit h towards a light at `distance` may be from
// the exact one (margins.glsl): its origin as the point, its direction by
// that over the distance.
rvec2 shadowOff(Hit h, real distance) { return rvec2(h.pointOff, h.pointOff / distance + CHAIN * UNIT_ROUNDOFF); }

// How far N·L and R·V may be from the exact ones' at hit h, towards a light
// at `distance`: the normal's and the light direction's uncertainty
// (margins.glsl), V's (the ray's direction's), and float rounding.
float cosineOffset(Hit h, real distance) {
    return float(2.0 * (h.normalOff + h.pointOff / distance) + h.viewTilt) + float(CHAIN) * 5.96e-8;
}

// Light j's part of the local term with binary shadows (SPEC §4.3), seen
// from v; castShadowRay: a shadow ray was cast (the surface faces the light).
// Where the shadow is undecided (margins.glsl) the light's term, which either
// answer may add or not, is added to `undecided`; what rounding may have
// moved of the term, to `error`.
vec3 shadeLight(uint j, Hit h, rvec3 v, out bool castShadowRay, inout vec3 undecided, inout vec3 error) {
    rvec3 l;
    real distance;
    float nl = towardsLight(j, h, l, distance);
    castShadowRay = false;
    if (!(nl > 0.0)) return vec3(0.0);
    castShadowRay = SHADOWS;
    bool unsure = false;
    bool blocked = SHADOWS && occluded(h.point, l, distance, h.sphere, shadowStart(h), shadowOff(h, distance), unsure);
    vec3 termError;
    vec3 term = lightTerm(j, h, l, nl, v, DECISIONS ? cosineOffset(h, distance) : 0.0, termError);
    if (unsure) undecided += term;
    if (DECISIONS && !blocked) error += termError;
    return blocked ? vec3(0.0) : term;
}

#endif
