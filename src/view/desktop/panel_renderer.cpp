#include "view/desktop/panel_renderer.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

#include <imgui.h>

#include "gpu/context.h"
#include "gpu/shared_types.h"

namespace pointrast::view {

// The shaders read ImDrawVert as 5 uints (position, uv, RGBA8) and indices as 16-bit halves of uints.
static_assert(sizeof(ImDrawVert) == 20 && offsetof(ImDrawVert, col) == 16);
static_assert(sizeof(ImDrawIdx) == 2);

namespace {

gpu::GraphicsOptions panelOptions(VkFormat colorFormat) {
  gpu::GraphicsOptions options;
  options.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  options.colorFormat = colorFormat;
  options.depthFormat = VK_FORMAT_UNDEFINED;
  options.blend = true;
  return options;
}

// Grows an upload buffer to hold `bytes` (at least 64 KiB, doubling), keeping it otherwise.
void reserve(gpu::Context& context, gpu::Buffer& buffer, uint64_t bytes, const char* name) {
  if (buffer && buffer.size() >= bytes) return;
  uint64_t size = std::max<uint64_t>(64 << 10, buffer ? buffer.size() : 0);
  while (size < bytes)
    size *= 2;
  buffer = gpu::Buffer(context, size, gpu::kBufferUsage, gpu::MemoryKind::Upload, name);
}

} // namespace

PanelRenderer::PanelRenderer(gpu::Context& context, VkFormat colorFormat)
    : context_(context), program_(context, "view_panel.vert", "view_panel.frag", panelOptions(colorFormat)) {
  ImGuiIO& io = ImGui::GetIO();
  unsigned char* pixels = nullptr;
  int width = 0, height = 0;
  io.Fonts->GetTexDataAsAlpha8(&pixels, &width, &height);
  fontWidth_ = uint32_t(width);
  fontHeight_ = uint32_t(height);
  uint64_t bytes = uint64_t(width) * uint64_t(height);
  font_ = gpu::Buffer(context, (bytes + 3) / 4 * 4, gpu::kBufferUsage, gpu::MemoryKind::Upload, "panel font");
  std::memcpy(font_.mapped(), pixels, bytes);
  // Any non-null id: there is one texture, the atlas, and draws never name another.
  io.Fonts->SetTexID(reinterpret_cast<ImTextureID>(intptr_t(1)));
}

void PanelRenderer::setImage(uint32_t width, uint32_t height, const uint32_t* rgba) {
  const uint64_t bytes = uint64_t(width) * height * 4;
  image_ = gpu::Buffer(context_, std::max<uint64_t>(bytes, 4), gpu::kBufferUsage, gpu::MemoryKind::Upload,
                       "panel image");
  std::memcpy(image_.mapped(), rgba, bytes);
  imageWidth_ = width;
  imageHeight_ = height;
}

void PanelRenderer::upload(const ImDrawData& data) {
  uint64_t vertexBytes = uint64_t(data.TotalVtxCount) * sizeof(ImDrawVert);
  // Indices are read two to a uint: round up so the last half-read stays inside the buffer.
  uint64_t indexBytes = (uint64_t(data.TotalIdxCount) * sizeof(ImDrawIdx) + 7) / 4 * 4;
  if (vertexBytes == 0) return;
  reserve(context_, vertices_, vertexBytes, "panel vertices");
  reserve(context_, indices_, indexBytes, "panel indices");
  auto* v = static_cast<char*>(vertices_.mapped());
  auto* i = static_cast<char*>(indices_.mapped());
  for (int n = 0; n < data.CmdListsCount; ++n) {
    const ImDrawList* list = data.CmdLists[n];
    std::memcpy(v, list->VtxBuffer.Data, size_t(list->VtxBuffer.Size) * sizeof(ImDrawVert));
    std::memcpy(i, list->IdxBuffer.Data, size_t(list->IdxBuffer.Size) * sizeof(ImDrawIdx));
    v += size_t(list->VtxBuffer.Size) * sizeof(ImDrawVert);
    i += size_t(list->IdxBuffer.Size) * sizeof(ImDrawIdx);
  }
}

void PanelRenderer::record(VkCommandBuffer cmd, const ImDrawData& data, uint32_t width, uint32_t height) {
  if (data.TotalVtxCount == 0) return;
  shared::PanelPush push{};
  push.vertices = vertices_.address();
  push.indices = indices_.address();
  push.font = font_.address();
  push.fontWidth = fontWidth_;
  push.fontHeight = fontHeight_;
  push.scaleX = 2.0f / float(width);
  push.scaleY = 2.0f / float(height);
  uint32_t vertexBase = 0, indexBase = 0;
  for (int n = 0; n < data.CmdListsCount; ++n) {
    const ImDrawList* list = data.CmdLists[n];
    for (const ImDrawCmd& draw : list->CmdBuffer) {
      if (draw.UserCallback) continue; // the panel registers none
      // The clip rectangle, in pixels, clamped to the target; nothing to draw when it is empty.
      float x0 = std::max(draw.ClipRect.x, 0.0f), y0 = std::max(draw.ClipRect.y, 0.0f);
      float x1 = std::min(draw.ClipRect.z, float(width)), y1 = std::min(draw.ClipRect.w, float(height));
      if (x1 <= x0 || y1 <= y0) continue;
      VkRect2D scissor{{int32_t(x0), int32_t(y0)}, {uint32_t(x1 - x0), uint32_t(y1 - y0)}};
      gpu::vkCmdSetScissor(cmd, 0, 1, &scissor);
      const bool image = draw.TextureId == reinterpret_cast<ImTextureID>(kImageId) && image_;
      push.image = image ? 1 : 0;
      push.font = image ? image_.address() : font_.address();
      push.fontWidth = image ? imageWidth_ : fontWidth_;
      push.fontHeight = image ? imageHeight_ : fontHeight_;
      push.firstIndex = indexBase + draw.IdxOffset;
      push.vertexOffset = vertexBase + draw.VtxOffset;
      program_.draw(cmd, draw.ElemCount, push);
    }
    vertexBase += uint32_t(list->VtxBuffer.Size);
    indexBase += uint32_t(list->IdxBuffer.Size);
  }
}

} // namespace pointrast::view
