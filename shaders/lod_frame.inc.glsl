// The buffers of a LOD frame (shared.h, "Level of detail"), for its drawing passes and its resolve.
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer LodFrameRef { LodFrame f; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer LodNodes { LodNode v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer LodPages { LodPage v[]; };

// Byte offset of a page's colors.
const uint kLodPageColors = 3u * kLodPageSectionBytes;
