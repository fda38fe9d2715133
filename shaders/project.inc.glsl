// The image contract of docs/design.md, in one place for every point method:
//   px = floor((c.x / c.w + 1) / 2 * W),  py = floor((1 - c.y / c.w) / 2 * H),  row 0 at the top;
//   a point is dropped if c.w <= near or the pixel is outside the image; the closest c.w wins.
// Returns false for a dropped point; otherwise the pixel index and the depth bits for the high word. The
// image may be a window of a wider framebuffer (a stereo eye): its pixel (px, py) is then element
// offset + py * pitch + px.
bool projectPointInto(mat4 viewProj, vec3 p, uint width, uint height, uint pitch, uint offset, float nearW,
                      out uint pixel, out uint depthBits) {
  // Out parameters are written on every path: GLSL copies an out parameter back to the caller even when
  // the function never assigned it, so an early return would hand the caller an undefined pixel.
  pixel = 0xFFFFFFFFu;
  depthBits = 0xFFFFFFFFu;
  vec4 c = viewProj * vec4(p, 1.0);
  if (!(c.w > nearW)) return false; // also drops NaN
  float fx = (c.x / c.w + 1.0) * 0.5 * float(width);
  float fy = (1.0 - c.y / c.w) * 0.5 * float(height);
  // Compare as floats before converting: a huge or NaN coordinate must not wrap into the image.
  if (!(fx >= 0.0 && fx < float(width) && fy >= 0.0 && fy < float(height))) return false;
  uint px = min(uint(fx), width - 1);
  uint py = min(uint(fy), height - 1);
  pixel = offset + py * pitch + px;
  depthBits = floatBitsToUint(c.w);
  return true;
}

bool projectPoint(mat4 viewProj, vec3 p, uint width, uint height, float nearW, out uint pixel,
                  out uint depthBits) {
  return projectPointInto(viewProj, p, width, height, width, 0u, nearW, pixel, depthBits);
}
