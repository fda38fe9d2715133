// Ray-cast sphere impostors: the geometry and shading every sphere pipeline shares (compute passes now,
// fragment shaders of the hardware pipelines later). src/render/spheres/cpu_spheres.cpp evaluates the
// same formulas in double precision as the independent reference; change both together.
//
// Camera (docs/design.md, "Camera and image"): view space is right-handed, looking down -z. The view ray of a
// pixel position p (pixel centers at +0.5, row 0 at the top) is dir = (p.x * sx + ox, p.y * sy + oy, -1)
// from the eye, which is the inverse of px = (c.x / c.w + 1) / 2 * W, py = (1 - c.y / c.w) / 2 * H of the
// point methods. With dir.z = -1 the point t * dir lies at view depth t: the ray parameter of a hit *is*
// its linear view depth (clip w), the depth the point methods compare, not the Euclidean distance.
// Only pixel centers are sampled: a sphere covers a pixel when the ray through its center hits it.

vec3 sphereRay(vec4 pixelToRay, vec2 pixel) {
  return vec3(pixel.x * pixelToRay.x + pixelToRay.y, pixel.y * pixelToRay.z + pixelToRay.w, -1.0);
}

// The inverse: the pixel position of the view-space point at xy / depth = slope.
vec2 rayPixel(vec4 pixelToRay, vec2 slope) {
  return (slope - pixelToRay.yw) / pixelToRay.xz;
}

// Nearest hit t > 0 of the ray t * dir with a sphere that lies entirely in front of the eye (callers cull
// the others). Numerically robust form of Haines, Guenther and Akenine-Moeller, "Precision Improvements
// for Ray/Sphere Intersection" (Ray Tracing Gems, ch. 7):
//   - the discriminant is r^2 - |v|^2, v the vector from the center to the closest point on the ray,
//     instead of b^2 - a c, which for a small sphere far away subtracts two numbers that agree in most
//     of their digits (and says "miss" for pixels in the middle of the sphere);
//   - the near root is c / q with q = b + sqrt(a * disc): no subtraction of nearly equal numbers either.
// discFloor > 0 asks for a ray that passes at least that far inside (disc = r^2 - |v|^2 >= discFloor); 0 is
// the plain hit test.
bool intersectSphereWithin(vec3 center, float radius, vec3 dir, float discFloor, out float depth) {
  depth = 0.0;
  float a = dot(dir, dir);
  float b = dot(center, dir); // > 0 for every ray that hits a sphere in front of the eye
  vec3 v = center - (b / a) * dir;
  float r2 = radius * radius;
  float disc = r2 - dot(v, v);
  if (!(disc >= discFloor && b > 0.0)) return false;
  float c = dot(center, center) - r2; // > 0: the eye is outside the sphere
  depth = c / (b + sqrt(a * disc));
  return depth > 0.0;
}

bool intersectSphere(vec3 center, float radius, vec3 dir, out float depth) {
  return intersectSphereWithin(center, radius, dir, 0.0, depth);
}

// Exact screen bounds of a sphere's perspective projection (an ellipse) as pixel positions
// (xmin, ymin, xmax, ymax), unclamped. The bounding lines are the tangent planes through the eye: along x,
// the slope s = x / depth of a tangent satisfies (cx - s d)^2 = r^2 (1 + s^2), d = -cz > r, so
//   s = (cx d -+ r sqrt(cx^2 + d^2 - r^2)) / (d^2 - r^2)
// (Mara and McGuire, "2D Polyhedral Bounds of a Clipped, Perspective-Projected 3D Sphere", 2013), and the
// same along y; a slope maps to the pixel position (s - ox) / sx.
vec4 sphereScreenBounds(vec3 center, float radius, vec4 pixelToRay) {
  float d = -center.z;
  float k = (d - radius) * (d + radius);
  vec2 c = center.xy;
  vec2 root = radius * sqrt(c * c + vec2(k));
  vec2 p0 = ((c * d - root) / k - pixelToRay.yw) / pixelToRay.xz;
  vec2 p1 = ((c * d + root) / k - pixelToRay.yw) / pixelToRay.xz;
  return vec4(min(p0, p1), max(p0, p1)); // sy < 0 flips y
}

// Headlight shading of the hit at view depth `depth` on the ray dir: the light sits at the eye, so
// color * (ambient + diffuse * max(dot(normal, toEye), 0)) is color where the surface faces the eye and
// the ambient share at the silhouette. Alpha passes through (spheres are opaque; nothing is blended).
vec4 shadeSphere(vec3 center, vec3 dir, float depth, vec4 color) {
  vec3 normal = normalize(depth * dir - center);
  float lambert = max(dot(normal, normalize(-dir)), 0.0);
  return vec4(color.rgb * (PR_SPHERE_AMBIENT + PR_SPHERE_DIFFUSE * lambert), color.a);
}
