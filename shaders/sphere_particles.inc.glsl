// What every sphere shader shares: the frame constants, particle loading in every layout of shared.h
// (LAYOUT is specialization constant 0 of every sphere shader), the view-space sphere with its culling,
// and its pixel box. The entry file declares the push constants and loads `frame`.
#include "common.inc.glsl"
#include "sphere_shade.inc.glsl"

layout(constant_id = 0) const uint LAYOUT = kSphereLayoutVec4x2;

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SphereFrameRef {
  SphereFrame f;
};
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer PartTable {
  SpherePartRef v[];
};
// The frame constants, loaded once per invocation by main().
SphereFrame frame;

struct Sphere {
  vec3 center;  // relative to the particle set's origin, world axes
  float radius;
  vec4 color;   // RGBA in [0, 1]
};

// Particle i of a part of `count` particles at `part` (byte layouts in shared.h).
Sphere loadSphere(uint64_t part, uint count, uint i) {
  Sphere s;
  if (LAYOUT == kSphereLayoutSoa8) {
    FloatArray f = FloatArray(part);
    s.center = vec3(f.v[i], f.v[count + i], f.v[2 * count + i]);
    s.radius = f.v[3 * count + i];
    s.color = vec4(f.v[4 * count + i], f.v[5 * count + i], f.v[6 * count + i], f.v[7 * count + i]);
  } else if (LAYOUT == kSphereLayoutVec4x2) {
    Vec4Array a = Vec4Array(part);
    vec4 p = a.v[i];
    s.center = p.xyz;
    s.radius = p.w;
    s.color = a.v[count + i];
  } else if (LAYOUT == kSphereLayoutAos) {
    // Read as integers: the color's bits must not pass through a float register.
    uvec4 p = Uvec4Array(part).v[i];
    s.center = uintBitsToFloat(p.xyz);
    s.radius = frame.globalRadius;
    s.color = unpackUnorm4x8(p.w);
  } else {
    FloatArray f = FloatArray(part);
    s.center = vec3(f.v[3 * i], f.v[3 * i + 1], f.v[3 * i + 2]);
    s.radius = frame.globalRadius;
    s.color = unpackUnorm4x8(frame.globalColor);
  }
  return s;
}

// Particle `index` of the whole set, through the part table.
Sphere sphereByIndex(uint index) {
  uint part = index / frame.partCapacity;
  SpherePartRef ref = PartTable(frame.parts).v[part];
  return loadSphere(ref.address, ref.count, index - part * frame.partCapacity);
}

// Whether a center has finite coordinates and the radius is a positive finite number (written so that NaN
// fails): the spheres any method draws.
bool finiteSphere(vec3 center, float radius) {
  const float kHuge = 3.0e38;
  return all(lessThan(abs(center), vec3(kHuge))) && radius > 0.0 && radius < kHuge;
}

// The sphere's center in view space; false if the sphere is culled: not entirely beyond the near plane
// (center depth - radius <= nearW: crossing spheres are dropped whole, never clipped), or with a
// non-finite coordinate or a radius that is not a positive finite number. Comparisons are written so
// that NaN fails them.
bool viewSphere(Sphere s, out vec3 center) {
  center = (frame.view * vec4(s.center, 1.0)).xyz;
  return finiteSphere(center, s.radius) && -center.z - s.radius > frame.nearW;
}

// Pixels whose centers the sphere may cover, clamped to the image: (x0, y0, x1, y1), empty when x1 < x0
// or y1 < y0 (the sphere is outside the frustum). A center p + 0.5 inside the exact bounds needs
// ceil(min - 0.5) <= p <= floor(max - 0.5); the 1/8-pixel margin absorbs the rounding of the bounds, the
// ray test decides.
ivec4 spherePixelBox(vec3 center, float radius) {
  vec4 b = sphereScreenBounds(center, radius, frame.pixelToRay);
  if (any(isnan(b))) return ivec4(0, 0, -1, -1);
  const float kMargin = 0.125;
  vec2 lo = clamp(ceil(b.xy - 0.5 - kMargin), vec2(0.0), vec2(frame.width, frame.height));
  vec2 hi = clamp(floor(b.zw - 0.5 + kMargin), vec2(-1.0), vec2(frame.width - 1, frame.height - 1));
  return ivec4(lo, hi);
}
