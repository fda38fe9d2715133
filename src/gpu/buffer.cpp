#include "gpu/buffer.h"

#include <cstring>
#include <utility>

#include "base/error.h"
#include "base/parallel_copy.h"
#include "gpu/context.h"

namespace pointrast::gpu {

namespace {

std::string gib(uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f GiB", double(bytes) / double(1ull << 30));
  return text;
}

} // namespace

uint32_t findMemoryType(const Context& context, uint32_t allowed, MemoryKind kind, bool& coherent) {
  const VkPhysicalDeviceMemoryProperties& mem = context.memoryProperties();
  auto find = [&](VkMemoryPropertyFlags want) -> int {
    for (uint32_t t = 0; t < mem.memoryTypeCount; ++t)
      if ((allowed & (1u << t)) && (mem.memoryTypes[t].propertyFlags & want) == want) return int(t);
    return -1;
  };
  int type = -1;
  switch (kind) {
  case MemoryKind::Device:
    type = find(VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    break;
  case MemoryKind::Upload:
    type = find(VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    break;
  case MemoryKind::Readback:
    type = find(VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    if (type < 0) type = find(VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
    break;
  }
  if (type < 0 && kind == MemoryKind::Device) type = find(0);
  if (type < 0) throw UnsupportedError("device '" + context.info().name + "' has no suitable memory type");
  coherent = mem.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  return uint32_t(type);
}

Buffer::Buffer(Context& context, uint64_t size, VkBufferUsageFlags usage, MemoryKind kind,
               const std::string& name)
    : device_(context.device()), size_(size) {
  if (size == 0) size = 4; // Vulkan forbids empty buffers; an empty scene part still gets a handle.
  if (size > context.maxBufferSize() || size > context.maxAllocationSize())
    throw UnsupportedError("buffer '" + name + "' of " + gib(size) +
                           " exceeds the device's largest buffer (" +
                           gib(std::min(context.maxBufferSize(), context.maxAllocationSize())) + ")");
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VK_CHECK(vkCreateBuffer(device_, &info, nullptr, &buffer_));
  try {
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, buffer_, &req);
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags =
        (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) ? VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT : 0;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = findMemoryType(context, req.memoryTypeBits, kind, coherent_);
    VkResult r = vkAllocateMemory(device_, &alloc, nullptr, &memory_);
    if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
      throw UnsupportedError("out of " + std::string(r == VK_ERROR_OUT_OF_DEVICE_MEMORY ? "GPU" : "host") +
                             " memory allocating " + gib(size) + " for '" + name +
                             "' (device memory: " + gib(context.deviceLocalBytes()) + ")");
    VK_CHECK(r);
    VK_CHECK(vkBindBufferMemory(device_, buffer_, memory_, 0));
    if (kind != MemoryKind::Device) VK_CHECK(vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
    if (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) {
      VkBufferDeviceAddressInfo addr{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
      addr.buffer = buffer_;
      address_ = vkGetBufferDeviceAddress(device_, &addr);
    }
    context.setName(VK_OBJECT_TYPE_BUFFER, uint64_t(buffer_), name);
    context.setName(VK_OBJECT_TYPE_DEVICE_MEMORY, uint64_t(memory_), name + " memory");
  } catch (...) {
    release();
    throw;
  }
}

Buffer::~Buffer() {
  release();
}

void Buffer::release() {
  if (deviceFaulted()) return; // the GPU may still use it: leave it to process exit
  if (buffer_) vkDestroyBuffer(device_, buffer_, nullptr);
  if (memory_) vkFreeMemory(device_, memory_, nullptr);
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
}

Buffer::Buffer(Buffer&& other) noexcept {
  *this = std::move(other);
}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    release();
    device_ = other.device_;
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    size_ = other.size_;
    address_ = other.address_;
    mapped_ = std::exchange(other.mapped_, nullptr);
    coherent_ = other.coherent_;
  }
  return *this;
}

void Buffer::invalidate() const {
  if (coherent_ || !mapped_) return;
  VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
  range.memory = memory_;
  range.size = VK_WHOLE_SIZE;
  VK_CHECK(vkInvalidateMappedMemoryRanges(device_, 1, &range));
}

void fullBarrier(VkCommandBuffer cmd) {
  VkMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
  barrier.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  barrier.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
  barrier.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT | VK_PIPELINE_STAGE_2_HOST_BIT;
  barrier.dstAccessMask =
      VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT | VK_ACCESS_2_HOST_READ_BIT;
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.memoryBarrierCount = 1;
  dep.pMemoryBarriers = &barrier;
  vkCmdPipelineBarrier2(cmd, &dep);
}

void readBuffer(Context& context, const Buffer& source, uint64_t offset, void* destination, uint64_t size,
                std::unique_ptr<Buffer>* kept) {
  if (size == 0) return;
  std::unique_ptr<Buffer> temporary;
  std::unique_ptr<Buffer>& staging = kept ? *kept : temporary;
  if (!staging || staging->size() != size)
    staging = std::make_unique<Buffer>(context, size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::Readback,
                                       "readback staging");
  context.submitAndWait([&](VkCommandBuffer cmd) {
    fullBarrier(cmd);
    VkBufferCopy region{offset, 0, size};
    vkCmdCopyBuffer(cmd, source.handle(), staging->handle(), 1, &region);
    fullBarrier(cmd);
  });
  staging->invalidate();
  copyOnAllThreads(destination, staging->mapped(), size);
}

void writeBuffer(Context& context, const Buffer& target, uint64_t offset, const void* source, uint64_t size) {
  if (size == 0) return;
  Buffer staging(context, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryKind::Upload, "upload staging");
  std::memcpy(staging.mapped(), source, size);
  context.submitAndWait([&](VkCommandBuffer cmd) {
    fullBarrier(cmd);
    VkBufferCopy region{0, offset, size};
    vkCmdCopyBuffer(cmd, staging.handle(), target.handle(), 1, &region);
    fullBarrier(cmd);
  });
}

} // namespace pointrast::gpu
