// The camera ray of a sub-pixel sample (SPEC §3).
#ifndef SNELL_PHYSICS_CAMERA_GLSL
#define SNELL_PHYSICS_CAMERA_GLSL

// SPEC §3: sub-pixel sample k of pixel p: the ray through
// (i + (a+½)/s, j + (b+½)/s), from the eye, starting at distance D along it.
Ray cameraRay(uvec2 p, uint k) {
    // k = b·s + a with k < s² ≤ 64²: b is exact from float division.
    float s = float(frame.supersample);
    float b = floor((float(k) + 0.5) / s);
    rvec2 ab = rvec2(float(k) - b * s, b);
    rvec2 q = rvec2(p) + (ab + 0.5) / real(s);
    rvec3 corner = WIDE(frame.cornerDir, frameLow.cornerDir).xyz;
    rvec3 right = WIDE(frame.pixelRight, frameLow.pixelRight).xyz;
    rvec3 down = WIDE(frame.pixelDown, frameLow.pixelDown).xyz;
    rvec3 dir = normalize(corner + q.x * right + q.y * down);
    rvec4 primaryStart = WIDE(frame.primaryStart, frameLow.primaryStart);
    rvec3 origin = primaryStart.xyz + primaryStart.w * dir;
    rvec2 off = CHAIN * UNIT_ROUNDOFF * rvec2(length(origin), 1.0);
    return Ray(origin, dir, vec3(1.0), 0u, NONE, false, 0u, 0u, off, false);
}


#endif
