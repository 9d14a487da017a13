// The shader's working precision for geometry (issue 4, --precision): float32
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
