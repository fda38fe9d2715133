// The vertex side of the rasterization sphere pipelines (sphere-points, sphere-triangles, sphere-strip,
// sphere-geom): each sphere becomes an impostor, an axis-aligned rectangle on screen at the depth of its
// front, and sphere_impostor.frag.glsl ray-casts every pixel it covers. BILLBOARD picks the rectangle:
//   kSphereBillboardScreen  the exact bounds of the sphere's projection (sphereScreenBounds)
//   kSphereBillboardCamera  the camera-aligned square of sphereCameraSquare
// The entry file loads `frame` first thing.
#include "sphere_particles.inc.glsl"

layout(push_constant) uniform Push { SpherePush pc; };
layout(constant_id = 2) const uint BILLBOARD = kSphereBillboardScreen;

// The camera-aligned billboard as pixel positions (xmin, ymin, xmax, ymax): the square through the center
// parallel to the image plane (sides along the camera's x and y axes, all at the center's view depth
// d = -cz > r, so no corner nears the eye and its projection is a square around the projected center).
// A square of side 2r is too small under perspective: the eye sees the sphere inside the cone of its
// tangent planes, which widens beyond r before it reaches the center's depth. Along x, the tangent planes
// through the eye have slopes s = (cx d -+ r sqrt(cx^2 + d^2 - r^2)) / (d^2 - r^2) (sphereScreenBounds),
// so at depth d the cone spans x = s d, and the square covers it when its half side h reaches
//   max(s1 d - cx, cx - s0 d) = r (d sqrt(cx^2 + d^2 - r^2) + |cx| r) / (d^2 - r^2),
// likewise along y; h is the larger of the two. On the view axis (cx = cy = 0) that is r d / sqrt(d^2 -
// r^2), side 2r grown by 1 / cos of the cone's half angle; off the axis the |cx| r term grows it further
// (cx = d, the edge of a 90-degree view: h ~ r (sqrt(2) + r / d), where the exact bounds are an ellipse
// stretched along x). The corners (cx +- h, cy +- h, cz) map to pixels as points do: (x / d - o) / s.
vec4 sphereCameraSquare(vec3 center, float radius, vec4 pixelToRay) {
  float d = -center.z;
  float k = (d - radius) * (d + radius);
  vec2 c = center.xy;
  vec2 reach = radius * (d * sqrt(c * c + vec2(k)) + abs(c) * radius) / k;
  float h = max(reach.x, reach.y);
  vec2 p0 = rayPixel(pixelToRay, (c - h) / d);
  vec2 p1 = rayPixel(pixelToRay, (c + h) / d);
  return vec4(min(p0, p1), max(p0, p1)); // sy < 0 flips y
}

// The ray test decides coverage; the impostor only has to contain every pixel center the sphere may
// cover. A quarter pixel absorbs the rounding of the bounds and the rasterizer's subpixel snapping (with
// conservative rasterization it only widens the touched pixels a little).
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
  vec4 b = BILLBOARD == kSphereBillboardCamera ? sphereCameraSquare(center, s.radius, frame.pixelToRay)
                                                : sphereScreenBounds(center, s.radius, frame.pixelToRay);
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
