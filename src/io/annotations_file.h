// The annotations file: measurements, labels and clip volumes (cloud/annotations.h) as one JSON object,
//   {"version": 1, "unit": "m", "annotations": [{"type": "distance", "points": [[x, y, z], ...],
//    "text": "...", "color": [r, g, b], "measured": {...}}, ...]}
// in the cloud's world coordinates. Doubles are written with the digits that read back the same value, so
// load(save(a)) == a. "measured" holds the values for a reader of the file; loading ignores it and measures
// again. The format is documented in docs/tools.md ("Measurements and annotations").
#pragma once

#include <filesystem>
#include <string>

#include "cloud/annotations.h"

namespace pointrast::io {

inline constexpr int kAnnotationsVersion = 1;
// An annotations file larger than this is refused before it is read (millions of annotations).
inline constexpr uint64_t kMaxAnnotationsFileBytes = uint64_t(64) << 20;
// A text longer than this is refused (a label is a few words).
inline constexpr size_t kMaxAnnotationText = 1000;

// Parses the text of an annotations file; `name` names it in errors. Throws InputError with one line that
// names the entry ("annotation 3 (distance): needs at least 2 points, not 1").
Annotations parseAnnotations(const std::string& text, const std::string& name);
// The JSON text of the annotations, "measured" included. Every annotation must be valid
// (annotationProblem empty: an assert).
std::string annotationsJson(const Annotations& annotations);

// Reads and parses a file; InputError for a missing, oversized or invalid one.
Annotations loadAnnotations(const std::filesystem::path& file);
// Writes under a temporary name and renames it into place; InputError when it cannot be written.
void saveAnnotations(const std::filesystem::path& file, const Annotations& annotations);

} // namespace pointrast::io
