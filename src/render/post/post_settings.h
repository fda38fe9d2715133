// What the resolve stage does to a frame (RenderSettings::post): points larger than a pixel, depth-aware
// dilation and eye-dome lighting, applied after any point method's raster and resolve. Defaults do
// nothing, and a frame without post-processing costs nothing extra.
#pragma once

#include <cstdint>
#include <string_view>

namespace pointrast {

enum class PointShape {
  Square, // side n pixels (n rounded): from -(n-1)/2 to n/2 pixels around the point's pixel
  Disc,   // pixels whose center is within half the size of the point's pixel center
};

enum class PointSizeMode {
  Fixed,      // every point is pointSize pixels
  Attenuated, // pointSize pixels at the camera target's distance, scaled by distance / depth like an
              // object of fixed world size, clamped to [1, maxPointSize]
  // As Potree: a world size from the spacing of the LOD level the point comes from. Needs a method that
  // knows each point's level (the LOD methods); their resolve would write the world spacing of each
  // pixel's point beside its word, and the splat pass read it as it reads the depth here. Refused until
  // then.
  Adaptive,
};

struct PostSettings {
  float pointSize = 1.0f; // pixels, 1 .. kMaxPointSize (shaders/shared.h)
  PointShape shape = PointShape::Square;
  PointSizeMode sizeMode = PointSizeMode::Fixed;
  float maxPointSize = 16.0f; // attenuated: the largest size, pixels (1 .. kMaxPointSize)
  uint32_t dilate = 0;        // dilation radius in pixels (window 2r+1 square); 0: off
  float edlStrength = 0.0f;   // eye-dome lighting; 0: off (Potree's default when on: 1)
  float edlRadius = 1.4f;     // eye-dome lighting's neighbour distance, pixels (Potree's default)

  bool splats() const { return sizeMode != PointSizeMode::Fixed || pointSize != 1.0f; }
  bool enabled() const { return splats() || dilate > 0 || edlStrength > 0.0f; }
};

// GPU time of each pass of the resolve stage, median over the timed frames (a pass not run: 0).
struct PostStats {
  double splatMs = 0, dilateMs = 0, composeMs = 0;
};

// "square"/"disc", "fixed"/"attenuated"/"adaptive"; throw InputError naming the choices.
PointShape parsePointShape(std::string_view name);
PointSizeMode parsePointSizeMode(std::string_view name);
const char* pointShapeName(PointShape shape);
const char* pointSizeModeName(PointSizeMode mode);

// Throws InputError for values out of range (sizes, radius, strength) and for the adaptive mode.
void validatePostSettings(const PostSettings& settings);

} // namespace pointrast
