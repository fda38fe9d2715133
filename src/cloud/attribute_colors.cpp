#include "cloud/attribute_colors.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "base/error.h"
#include "cloud/detail.h"

namespace pointrast {

namespace {

struct SourceName {
  DisplayColorMode::Source source;
  const char* name;
};
constexpr SourceName kSourceNames[] = {
    {DisplayColorMode::Source::Rgb, "rgb"},
    {DisplayColorMode::Source::Intensity, "intensity"},
    {DisplayColorMode::Source::Classification, "classification"},
    {DisplayColorMode::Source::Elevation, "elevation"},
    {DisplayColorMode::Source::ReturnNumber, "return"},
    {DisplayColorMode::Source::PointSource, "source"},
};

// ASPRS standard point classes (LAS 1.4 R15, Table 17). The standard names the classes, not their colors;
// these follow the conventions of common viewers: earth tones for ground, greens darkening with
// vegetation height, warm colors for buildings, blue for water, loud colors for noise and wires.
constexpr uint32_t kClassColors[23] = {
    packRgba(128, 128, 128), // 0  created, never classified
    packRgba(170, 170, 170), // 1  unclassified
    packRgba(166, 110, 60),  // 2  ground
    packRgba(160, 220, 110), // 3  low vegetation
    packRgba(70, 180, 60),   // 4  medium vegetation
    packRgba(20, 110, 30),   // 5  high vegetation
    packRgba(235, 140, 40),  // 6  building
    packRgba(255, 0, 255),   // 7  low point (noise)
    packRgba(200, 200, 0),   // 8  reserved (model key-point in LAS 1.1-1.3)
    packRgba(40, 110, 230),  // 9  water
    packRgba(140, 80, 160),  // 10 rail
    packRgba(90, 90, 90),    // 11 road surface
    packRgba(255, 230, 0),   // 12 reserved (overlap points in LAS 1.1-1.3)
    packRgba(255, 200, 150), // 13 wire - guard (shield)
    packRgba(255, 160, 0),   // 14 wire - conductor (phase)
    packRgba(200, 40, 40),   // 15 transmission tower
    packRgba(255, 110, 110), // 16 wire-structure connector (insulator)
    packRgba(120, 120, 170), // 17 bridge deck
    packRgba(255, 0, 128),   // 18 high noise
    packRgba(150, 100, 200), // 19 overhead structure
    packRgba(120, 90, 60),   // 20 ignored ground (breakline proximity)
    packRgba(240, 250, 255), // 21 snow
    packRgba(100, 100, 120), // 22 temporal exclusion
};

// Return numbers 1..7 (formats 0-5 store up to 5, 6-10 up to 15): first returns red, then green, blue,
// yellow, magenta, cyan; 7 and above white; 0 (no return number) gray.
constexpr uint32_t kReturnColors[8] = {
    packRgba(128, 128, 128), packRgba(230, 50, 40),  packRgba(40, 180, 60),  packRgba(50, 90, 230),
    packRgba(240, 200, 30),  packRgba(220, 60, 220), packRgba(40, 210, 220), packRgba(255, 255, 255),
};

uint32_t byte(double v) {
  return static_cast<uint32_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

// HSV (all in [0, 1]) to RGB.
uint32_t hsv(double h, double s, double v) {
  double f = h * 6.0;
  int sector = static_cast<int>(f) % 6;
  double frac = f - std::floor(f);
  double p = v * (1 - s), q = v * (1 - s * frac), t = v * (1 - s * (1 - frac));
  double r = v, g = t, b = p;
  switch (sector) {
  case 1:
    r = q, g = v, b = p;
    break;
  case 2:
    r = p, g = v, b = t;
    break;
  case 3:
    r = p, g = q, b = v;
    break;
  case 4:
    r = t, g = p, b = v;
    break;
  case 5:
    r = v, g = p, b = q;
    break;
  default:
    break;
  }
  return packRgba(byte(r), byte(g), byte(b));
}

// Position of `value` on a ramp over [lo, hi]; the middle when the range is empty.
double rampPosition(double value, const DisplayColorMode& mode) {
  const double span = mode.hi - mode.lo;
  return span > 0 ? (value - mode.lo) / span : 0.5;
}

} // namespace

DisplayColorMode::Source parseColorSource(std::string_view name) {
  for (const SourceName& s : kSourceNames)
    if (name == s.name) return s.source;
  throw InputError("unknown color mode '" + std::string(name) + "'; choose one of: " + colorSourceNames());
}

const char* colorSourceName(DisplayColorMode::Source source) {
  for (const SourceName& s : kSourceNames)
    if (s.source == source) return s.name;
  return "rgb";
}

const char* colorSourceNames() {
  return "rgb, intensity, classification, elevation, return, source";
}

uint32_t intensityColor(double t) {
  const uint32_t g = t > 0 ? byte(t) : 0; // also NaN
  return packRgba(g, g, g);
}

uint32_t elevationColor(double t) {
  return detail::rampColor(t);
}

uint32_t classificationColor(uint8_t classification) {
  if (classification < std::size(kClassColors)) return kClassColors[classification];
  // Reserved (23-63) and user-definable (64-255) classes: a hue of their own each.
  return hsv(std::fmod(classification * 0.6180339887498949, 1.0), 0.55, 0.9);
}

uint32_t returnNumberColor(uint8_t returnNumber) {
  return kReturnColors[std::min<size_t>(returnNumber, std::size(kReturnColors) - 1)];
}

uint32_t pointSourceColor(uint16_t pointSourceId) {
  // Multiples of the golden ratio modulo 1 spread over the circle with no two consecutive ids close.
  return hsv(std::fmod(pointSourceId * 0.6180339887498949, 1.0), 0.7, 0.95);
}

uint32_t attributeColor(const DisplayColorMode& mode, uint32_t rgb, uint16_t intensity, double z,
                        uint8_t classification, uint8_t returnNumber, uint16_t pointSourceId) {
  switch (mode.source) {
  case DisplayColorMode::Source::Rgb:
    return rgb | 0xFF000000u;
  case DisplayColorMode::Source::Intensity:
    return intensityColor(rampPosition(intensity, mode));
  case DisplayColorMode::Source::Elevation:
    return elevationColor(rampPosition(z, mode));
  case DisplayColorMode::Source::Classification:
    return classificationColor(classification);
  case DisplayColorMode::Source::ReturnNumber:
    return returnNumberColor(returnNumber);
  case DisplayColorMode::Source::PointSource:
    return pointSourceColor(pointSourceId);
  }
  return rgb | 0xFF000000u;
}

void recordColors(uint32_t* dst, const PointRecord* records, size_t count, const DisplayColorMode& mode,
                  double scaleZ, double offsetZ, int colorShift) {
  for (size_t i = 0; i < count; ++i) {
    const PointRecord& r = records[i];
    const uint32_t rgb = packRgba((r.rgb[0] >> colorShift) & 0xFF, (r.rgb[1] >> colorShift) & 0xFF,
                                  (r.rgb[2] >> colorShift) & 0xFF);
    dst[i] = attributeColor(mode, rgb, r.intensity, r.z * scaleZ + offsetZ, r.classification, r.returnNumber,
                            r.pointSourceId);
  }
}

} // namespace pointrast
