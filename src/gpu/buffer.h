// GPU buffers with their own memory. Every buffer can be addressed from shaders by device address, so
// shaders see no descriptor-range limit; the size limit is the device's largest allocation (scenes larger
// than that are split into parts by render/scene).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "gpu/vulkan_api.h"

namespace pointrast::gpu {

class Context;

enum class MemoryKind {
  Device,   // device-local, not mappable (scene data, framebuffers)
  Upload,   // host-visible, coherent, written by the CPU (staging)
  Readback, // host-visible, cached where possible, read by the CPU
};

class Buffer {
public:
  Buffer() = default;
  // Throws UnsupportedError with the size and the device's capacity when the memory cannot be had.
  Buffer(Context& context, uint64_t size, VkBufferUsageFlags usage, MemoryKind kind, const std::string& name);
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  VkBuffer handle() const { return buffer_; }
  uint64_t size() const { return size_; }
  uint64_t address() const { return address_; }
  // Mapped pointer for Upload/Readback buffers, null for Device buffers.
  void* mapped() const { return mapped_; }
  // Makes GPU writes visible to mapped() reads on non-coherent memory.
  void invalidate() const;
  explicit operator bool() const { return buffer_ != VK_NULL_HANDLE; }

private:
  void release();
  VkDevice device_ = VK_NULL_HANDLE;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  uint64_t size_ = 0;
  uint64_t address_ = 0;
  void* mapped_ = nullptr;
  bool coherent_ = true;
};

// A memory type of `kind` among the `allowed` bits (VkMemoryRequirements::memoryTypeBits); Device falls
// back to any allowed type on devices (lavapipe) whose types lack DEVICE_LOCAL. Sets coherent.
uint32_t findMemoryType(const Context& context, uint32_t allowed, MemoryKind kind, bool& coherent);

// Usage flags every buffer gets: device address, and transfer both ways (fills, copies, readback).
constexpr VkBufferUsageFlags kBufferUsage =
    VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
    VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

// A full memory barrier between two commands of a command buffer (compute/transfer/host -> all). Passes
// of this renderer are few and large, so precise barriers would buy nothing measurable.
void fullBarrier(VkCommandBuffer cmd);

// Copies size bytes of a Device buffer into host memory through a readback buffer: a temporary one, or
// *kept (made, or remade when its size differs, and left there for the next read: what a caller reading
// every frame passes). The copy out of it runs on all threads.
void readBuffer(Context& context, const Buffer& source, uint64_t offset, void* destination, uint64_t size,
                std::unique_ptr<Buffer>* kept = nullptr);
// Copies size bytes of host memory into a Device buffer through a temporary upload buffer.
void writeBuffer(Context& context, const Buffer& target, uint64_t offset, const void* source, uint64_t size);

} // namespace pointrast::gpu
