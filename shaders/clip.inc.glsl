// Clip volumes on the GPU (shared.h, ClipVolumes): the rules of cloud/point_filter.h, evaluated on the float
// position a method already has (relative to the scene origin). Needs common.inc.glsl.
//   clipKeeps        per point: whether the clip keeps it (one uniform load and a branch without a clip)
//   clipBoxVerdict   per batch or node: whether every point of a box is kept, none is, or each must be
//                    tested; conservative like cloud/point_filter.h's clipVerdict (Some is always right)

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer ClipRef { ClipVolumes c; };

// Verdicts of clipBoxVerdict (the order of cloud/point_filter.h's BoxVerdict).
const uint kClipBoxNone = 0u;
const uint kClipBoxSome = 1u;
const uint kClipBoxAll = 2u;

// Vertex j of the polygons' vertex list.
vec2 clipVertex(ClipRef clip, uint j) {
  vec4 pair = clip.c.vertices[j >> 1u];
  return (j & 1u) == 0u ? pair.xy : pair.zw;
}

// Even-odd rule: a horizontal ray from p crosses the polygon's edges an odd number of times.
bool clipInPolygon(ClipRef clip, uint k, vec3 p) {
  vec4 poly = clip.c.polygon[k];
  if (!(p.z >= poly.z && p.z <= poly.w)) return false;
  uint first = floatBitsToUint(poly.x), count = floatBitsToUint(poly.y);
  bool inside = false;
  vec2 a = clipVertex(clip, first + count - 1u);
  for (uint i = 0u; i < count; ++i) {
    vec2 b = clipVertex(clip, first + i);
    if ((b.y > p.y) != (a.y > p.y) && p.x < (a.x - b.x) * (p.y - b.y) / (a.y - b.y) + b.x) inside = !inside;
    a = b;
  }
  return inside;
}

bool clipInside(ClipRef clip, vec3 p) {
  for (uint i = 0u; i < clip.c.boxes; ++i)
    if (all(greaterThanEqual(p, clip.c.box[2u * i].xyz)) && all(lessThanEqual(p, clip.c.box[2u * i + 1u].xyz)))
      return true;
  for (uint i = 0u; i < clip.c.orientedBoxes; ++i) {
    vec3 d = p - clip.c.oriented[4u * i].xyz;
    vec4 a0 = clip.c.oriented[4u * i + 1u], a1 = clip.c.oriented[4u * i + 2u], a2 = clip.c.oriented[4u * i + 3u];
    if (abs(dot(a0.xyz, d)) <= a0.w && abs(dot(a1.xyz, d)) <= a1.w && abs(dot(a2.xyz, d)) <= a2.w) return true;
  }
  for (uint i = 0u; i < clip.c.polygons; ++i)
    if (clipInPolygon(clip, i, p)) return true;
  return false;
}

// Whether the clip volumes of a RasterPush scene record (kSceneClipped in bit 0) keep the point p: without the
// bit, one test of a push constant.
bool sceneKeeps(uint64_t scene, vec3 p);

// Whether the clip volumes at `address` keep the point p.
bool clipKeeps(uint64_t address, vec3 p) {
  ClipRef clip = ClipRef(address);
  uint mode = clip.c.mode;
  if (mode == kClipNone) return true;
  return clipInside(clip, p) == (mode == kClipInside);
}

bool sceneKeeps(uint64_t scene, vec3 p) {
  return (scene & kSceneClipped) == 0ul || clipKeeps(scene & ~kSceneClipped, p);
}

// Relative slack of the box tests: a point's float position (decoded from its words, or rounded relative to
// the origin) and the float bounds of its box differ from the exact ones by a few ulps of their magnitude,
// far under 1e-5 of it; the box is widened by that much, so no verdict is wrong for a point of the box.
const float kClipMargin = 1e-5;

// How one volume relates to the box [lo, hi] (widened by e): kClipBoxNone, Some or All.
uint clipVolumeVerdict(ClipRef clip, uint kind, uint i, vec3 lo, vec3 hi, vec3 e) {
  if (kind == 0u) {
    vec3 bmin = clip.c.box[2u * i].xyz, bmax = clip.c.box[2u * i + 1u].xyz;
    if (any(lessThan(hi + e, bmin)) || any(greaterThan(lo - e, bmax))) return kClipBoxNone;
    if (all(greaterThanEqual(lo - e, bmin)) && all(lessThanEqual(hi + e, bmax))) return kClipBoxAll;
    return kClipBoxSome;
  }
  vec3 center = 0.5 * (lo + hi), half_ = 0.5 * (hi - lo) + e;
  if (kind == 1u) {
    vec3 c = clip.c.oriented[4u * i].xyz;
    vec3 reach = vec3(0.0); // the oriented box's half extent along each world axis
    bool all3 = true;
    for (uint k = 0u; k < 3u; ++k) {
      vec4 a = clip.c.oriented[4u * i + 1u + k];
      float d = abs(dot(a.xyz, center - c)), r = dot(abs(a.xyz), half_);
      float slack = kClipMargin * (d + r + a.w);
      if (d - r > a.w + slack) return kClipBoxNone; // separated along this axis of the oriented box
      all3 = all3 && d + r + slack <= a.w;
      reach += abs(a.xyz) * a.w;
    }
    if (any(greaterThan(abs(center - c), half_ + reach * (1.0 + kClipMargin)))) return kClipBoxNone;
    return all3 ? kClipBoxAll : kClipBoxSome;
  }
  // A polygon prism: only its z range and the bounding rectangle of its vertices decide None; a box inside
  // the prism is still tested point by point.
  vec4 poly = clip.c.polygon[i];
  if (hi.z + e.z < poly.z || lo.z - e.z > poly.w) return kClipBoxNone;
  uint first = floatBitsToUint(poly.x), count = floatBitsToUint(poly.y);
  vec2 pmin = vec2(3.0e38), pmax = vec2(-3.0e38);
  for (uint j = 0u; j < count; ++j) {
    vec2 v = clipVertex(clip, first + j);
    pmin = min(pmin, v);
    pmax = max(pmax, v);
  }
  if (any(lessThan(hi.xy + e.xy, pmin)) || any(greaterThan(lo.xy - e.xy, pmax))) return kClipBoxNone;
  return kClipBoxSome;
}

// Whether the clip volumes at `address` keep every point of the box [lo, hi] (kClipBoxAll), none
// (kClipBoxNone), or some (kClipBoxSome: each point is tested).
uint clipBoxVerdict(uint64_t address, vec3 lo, vec3 hi) {
  ClipRef clip = ClipRef(address);
  uint mode = clip.c.mode;
  if (mode == kClipNone) return kClipBoxAll;
  vec3 e = kClipMargin * (abs(lo) + abs(hi) + (hi - lo));
  bool none = true, all_ = false; // of the union: inside none of the volumes, inside one of them
  uint counts[3] = uint[3](clip.c.boxes, clip.c.orientedBoxes, clip.c.polygons);
  for (uint kind = 0u; kind < 3u && !all_; ++kind)
    for (uint i = 0u; i < counts[kind] && !all_; ++i) {
      uint v = clipVolumeVerdict(clip, kind, i, lo, hi, e);
      all_ = v == kClipBoxAll;
      none = none && v == kClipBoxNone;
    }
  uint inside = all_ ? kClipBoxAll : none ? kClipBoxNone : kClipBoxSome;
  return mode == kClipInside ? inside : kClipBoxAll - inside; // Outside swaps All and None
}
