// 16-byte words moved through a device address as two 64-bit halves. At
// per-lane addresses lavapipe gathers (and scatters) each component of a
// value on its own, so a word read as u64vec2 costs two gathers where a uvec4
// costs four: on Mesa 25 the BVH walk's floor ran 1.2–1.3× faster so
// (docs/log/kernel-profiled.md, "Words loaded as 64-bit halves"). Needs shaderInt64.
#ifndef SNELL_WIDE_WORDS_GLSL
#define SNELL_WIDE_WORDS_GLSL
#extension GL_ARB_gpu_shader_int64 : require

uvec4 fromHalves(u64vec2 w) { return uvec4(unpackUint2x32(w.x), unpackUint2x32(w.y)); }
u64vec2 toHalves(uvec4 v) { return u64vec2(packUint2x32(v.xy), packUint2x32(v.zw)); }

#endif
