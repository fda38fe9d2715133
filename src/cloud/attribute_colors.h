// Coloring by attribute (render --color): how each DisplayColorMode source maps a point onto RGBA8
// (packRgba, alpha 255). Colors are computed on the CPU when points are uploaded (GpuScene, and the LOD
// node cache through recordColors()), so every method, the blending ones included, draws them unchanged.
//
//   rgb            the file's colors (8-bit, or the high byte of 16-bit)
//   intensity      gray ramp, black at lo and white at hi (as Potree and CloudCompare show intensity)
//   elevation      Turbo ramp (cloud/detail.h rampColor) from lo to hi of world z
//   classification the ASPRS standard classes of LAS 1.4 R15 Table 17, colors in the .cpp
//   return         return number 1..7 on a categorical palette (0: not known)
//   source         point source id (the flight line or scan) on a golden-ratio walk around the hue circle,
//                  so consecutive ids get clearly different hues
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "cloud/cloud.h"
#include "cloud/point_record.h"

namespace pointrast {

// "rgb", "intensity", "elevation", "classification", "return", "source"; parse throws InputError listing
// them.
DisplayColorMode::Source parseColorSource(std::string_view name);
const char* colorSourceName(DisplayColorMode::Source source);
// The names joined with ", " (for help text and messages).
const char* colorSourceNames();

uint32_t intensityColor(double t); // t in [0, 1], clamped; NaN is 0
uint32_t elevationColor(double t); // t in [0, 1], clamped; NaN is 0
uint32_t classificationColor(uint8_t classification);
uint32_t returnNumberColor(uint8_t returnNumber);
uint32_t pointSourceColor(uint16_t pointSourceId);

// The color of one point given its attributes (those the mode does not read may be anything). rgb is
// packRgba of the point's own color; z is world elevation.
uint32_t attributeColor(const DisplayColorMode& mode, uint32_t rgb, uint16_t intensity, double z,
                        uint8_t classification, uint8_t returnNumber, uint16_t pointSourceId);

// Colors of records from an LOD source: the same mapping as displayColors() gives the points of a
// PointCloud. world z = record.z * scaleZ + offsetZ; colorShift is 8 for 16-bit colors, else 0.
void recordColors(uint32_t* dst, const PointRecord* records, size_t count, const DisplayColorMode& mode,
                  double scaleZ, double offsetZ, int colorShift);

} // namespace pointrast
