// Probe of a driver's loop limiter (host/gpu/DriverProbe.cpp): one invocation
// counts a loop of `iterations` passes. Mesa's llvmpipe before 24 stops every
// loop after 65535 passes per SIMD row and dispatch, silently; there the count
// comes back short.
#version 460
layout(local_size_x = 1) in;
layout(set = 0, binding = 0, std430) buffer ResultBlock { uint passes; };
layout(push_constant) uniform ProbeBlock { uint iterations; };

void main() {
    uint n = 0u;
    for (uint i = 0u; i < iterations; ++i) n++;
    passes = n;
}
