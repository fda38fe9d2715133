// The vertex side of the rasterization sphere pipelines (sphere-points, sphere-triangles, sphere-strip,
// sphere-geom): each sphere becomes a screen-aligned impostor covering the exact bounds of its projection
// (sphere_shade.inc.glsl) at the depth of its front, and sphere_impostor.frag.glsl ray-casts every pixel
// it covers. The entry file loads `frame` first thing.
#include "sphere_particles.inc.glsl"

layout(push_constant) uniform Push { SpherePush pc; };

// The ray test decides coverage; the impostor only has to contain every pixel center the sphere may
// cover. A quarter pixel absorbs the rounding of the bounds and the rasterizer's subpixel snapping.
const float kImpostorMargin = 0.25;

struct Impostor {
  bool visible;     // false: culled (near plane, bad values) or outside the frustum
  vec4 ndc;         // bounds in Vulkan NDC (x0, y0, x1, y1): y down, row 0 at y = -1
  float depth;      // reverse-Z of the sphere's front: nearW / (center depth - radius), in (0, 1)
  vec4 centerRadius; // view-space center and radius, for the fragment shader
  vec4 color;
  uint index;       // global particle index, kNoParticle when culled
};

Impostor sphereImpostor(uint local) {
  Impostor imp;
  Sphere s = loadSphere(pc.particles, pc.count, local);
  vec3 center;
  imp.visible = viewSphere(s, center);
  vec4 b = sphereScreenBounds(center, s.radius, frame.pixelToRay);
  b += vec4(-kImpostorMargin, -kImpostorMargin, kImpostorMargin, kImpostorMargin);
  // Outside the image: culled here rather than left to the clipper, which treats points by their center.
  imp.visible = imp.visible && !any(isnan(b)) && b.z > 0.0 && b.w > 0.0 && b.x < float(frame.width) &&
                b.y < float(frame.height);
  // Pixel position -> NDC: x = 2 px / W - 1, y = 2 py / H - 1 (the viewport maps y = -1 to row 0).
  vec2 scale = 2.0 / vec2(frame.width, frame.height);
  imp.ndc = b * scale.xyxy - 1.0;
  imp.depth = frame.nearW / (-center.z - s.radius);
  imp.centerRadius = vec4(center, s.radius);
  imp.color = s.color;
  imp.index = imp.visible ? pc.first + local : kNoParticle;
  return imp;
}

// A position outside the clip volume: a culled point is discarded, a culled quad clipped away whole.
const vec4 kCulledPosition = vec4(2.0, 2.0, 2.0, 1.0);
