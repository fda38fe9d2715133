#version 460
// hw-points (see points_hw.vert.glsl): the point's RGBA8 color (r | g << 8 | b << 16 | a << 24) into an
// R8G8B8A8_UNORM attachment; unpack then the attachment's rounding gives back the same bytes.
layout(location = 0) flat in uint color;
layout(location = 0) out vec4 outColor;

void main() { outColor = unpackUnorm4x8(color); }
