#version 460
// Copies the renderer's RGBA8 image into the swapchain image: the fragment at pixel (x, y) (Vulkan's
// framebuffer row 0 is the top, as in the image) takes the image's pixel (x, y), unchanged when the sizes
// agree. The target is a UNORM format, so the 8-bit values arrive exactly (BGRA or RGBA alike).
#include "common.inc.glsl"

layout(push_constant) uniform Push { PresentPush pc; };
layout(location = 0) out vec4 color;

void main() {
  uvec2 target = uvec2(gl_FragCoord.xy);
  // Nearest pixel while the image lags a resize by a frame.
  uvec2 source = min(target * uvec2(pc.imageWidth, pc.imageHeight) / uvec2(pc.targetWidth, pc.targetHeight),
                     uvec2(pc.imageWidth - 1, pc.imageHeight - 1));
  color = unpackUnorm4x8(UintArray(pc.image).v[source.y * pc.imageWidth + source.x]);
  color.a = 1.0;
}
