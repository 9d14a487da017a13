// The shader's working precision for geometry (--precision): float32
// by default; compiled with SNELL_FP64 defined, every position, direction and
// distance is a double (colours stay float). Scene data reaches an fp64 shader
// as float pairs, hi + lo (shared_layout.h), so it keeps 48 bits of the host's
// double values.
#ifndef SNELL_PRECISION_GLSL
#define SNELL_PRECISION_GLSL

#ifdef SNELL_FP64
#define real double
#define rvec2 dvec2
#define rvec3 dvec3
#define rvec4 dvec4
#define rmat3 dmat3
#define rmat4 dmat4
// Unit roundoff of double: 2^-53.
const real UNIT_ROUNDOFF = 1.1102230246251565e-16LF;

// v as the float pair hi + lo (48 bits of it). hi is v rounded to 24
// significant bits by Veltkamp's split (Dekker 1971), exact in double, rather
// than float(v): Mesa 25's llvmpipe folds double(float(v)) back into v, which
// would make lo 0 (and Mesa 22's mishandles packDouble2x32).
void splitDouble(double v, out float hi, out float lo) {
    precise double c = 536870913.0LF * v;  // 2^29 + 1: keeps 53 − 29 = 24 bits
    precise double h = c - (c - v);
    hi = float(h);  // exact
    lo = float(v - h);
}
void splitDouble(dvec3 v, out vec3 hi, out vec3 lo) {
    for (int k = 0; k < 3; ++k) splitDouble(v[k], hi[k], lo[k]);
}
// v as three floats, hi + mid + lo, exactly (24 + 24 + 5 of its 53 bits, as
// long as lo is within float's range): the split above, then the same split
// of its remainder v − hi, which has at most 29 bits. A ray that waits in a
// stack comes back as the very ray that was stored, so a render does not
// depend on which rays waited.
void splitDoubleExact(double v, out float hi, out float mid, out float lo) {
    precise double c = 536870913.0LF * v;
    precise double h = c - (c - v);
    precise double r = v - h;  // exact
    precise double d = 536870913.0LF * r;
    precise double m = d - (d - r);
    hi = float(h);
    mid = float(m);
    lo = float(r - m);  // exact: at most 5 bits
}
void splitDoubleExact(dvec3 v, out vec3 hi, out vec3 mid, out vec3 lo) {
    for (int k = 0; k < 3; ++k) splitDoubleExact(v[k], hi[k], mid[k], lo[k]);
}
#else
#define real float
#define rvec2 vec2
#define rvec3 vec3
#define rvec4 vec4
#define rmat3 mat3
#define rmat4 mat4
// Unit roundoff of float32: 2^-24.
const real UNIT_ROUNDOFF = 5.96e-8;
#endif

#endif
