// The device's floor: each invocation stores one vec4, the pixel's colour, and
// does nothing else: the least a dispatch that writes an image can cost.
// `snell bench` compares the renderer on an empty scene with it.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "kernel_layout.h"

layout(local_size_x = SNELL_KERNEL_GROUP_SIZE) in;
layout(set = 0, binding = 0, std430) writeonly buffer PixelBlock { vec4 pixels[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    pixels[i] = vec4(float(i & 255u) / 255.0, 0.5, 0.25, 1.0);
}
