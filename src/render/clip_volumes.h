// The clip volumes of a PointFilter as the GPU reads them (shared.h, ClipVolumes): relative to a scene's
// origin, rounded once to float. The renderer writes them for every scene of a frame.
#pragma once

#include <glm/glm.hpp>

#include "cloud/point_filter.h"
#include "gpu/shared_types.h"

namespace pointrast {

// Throws InputError when the filter holds more volumes or polygon vertices than the GPU table holds
// (shared.h: kMaxClipBoxes, kMaxClipOrientedBoxes, kMaxClipPolygons, kMaxClipVertices) or a polygon has fewer
// than 3 vertices. ClipMode::Highlight drops no point: mode kClipNone (the colors carry the highlight).
shared::ClipVolumes gpuClipVolumes(const PointFilter& filter, const glm::dvec3& origin);

// Throws InputError as gpuClipVolumes would, without building the table (the options' early check).
void checkGpuClip(const PointFilter& filter);

} // namespace pointrast
