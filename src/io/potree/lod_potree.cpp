#include "io/potree/lod_potree.h"

namespace pointrast::io {

namespace {

struct EncodedNode final : lod::PreparedNode {
  PotreeEncodedNode node;
  uint64_t offset = 0; // in octree.bin, from writePrepared()
  bool placed = false;
};

uint64_t folderBytes(const std::filesystem::path& dir) {
  uint64_t bytes = 0;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    // A size that cannot be read is left out rather than added as -1 (a size printed as "-101 bytes").
    std::error_code sizeError;
    if (!entry.is_regular_file(sizeError)) continue;
    const uintmax_t size = entry.file_size(sizeError);
    if (!sizeError) bytes += size;
  }
  return bytes;
}

} // namespace

void PotreeNodeSink::writeNode(const lod::NodeKey& key, const PointRecord* records, const uint8_t* tails,
                               size_t count) {
  writer_.writeNode(key, records, tails, count);
}

std::unique_ptr<lod::PreparedNode> PotreeNodeSink::prepare(const lod::NodeKey&, const PointRecord* records,
                                                           const uint8_t* tails, size_t count) const {
  auto encoded = std::make_unique<EncodedNode>();
  encoded->node = writer_.encodeNode(records, tails, count);
  return encoded;
}

void PotreeNodeSink::writePrepared(const lod::NodeKey& key, lod::PreparedNode* prepared,
                                   const PointRecord* records, const uint8_t* tails, size_t count) {
  auto* encoded = dynamic_cast<EncodedNode*>(prepared);
  if (!encoded) return writeNode(key, records, tails, count);
  encoded->offset = writer_.place(key, encoded->node);
  encoded->placed = true;
}

void PotreeNodeSink::finishPrepared(std::unique_ptr<lod::PreparedNode> prepared) const {
  auto* encoded = dynamic_cast<EncodedNode*>(prepared.get());
  if (encoded && encoded->placed) writer_.writeAt(encoded->offset, encoded->node);
}

PotreeBuildReport buildPotree(const std::vector<std::filesystem::path>& inputs,
                              const std::filesystem::path& output, const LodBuildOptions& options,
                              const PotreeWriteOptions& writeOptions) {
  OctreeBuilder builder(inputs, options);
  const lod::OctreeMetadata& metadata = builder.scan();
  PotreeWriteOptions withTail = writeOptions;
  withTail.tail = builder.tail();
  PotreeWriter writer(output, metadata, withTail);
  PotreeNodeSink sink(writer);
  PotreeBuildReport report;
  // Temporary chunk files live in the writer's folder: whatever ends the build, they go with it.
  report.build = builder.build(sink, writer.workingDir() / "chunks");
  for (lod::LodPhase& phase : report.build.phases)
    if (phase.name == "write") phase.bytes = writer.bytesWritten(); // octree.bin
  const lod::PhaseClock clock;
  writer.commit();
  report.build.phases.push_back(clock.done("commit", report.build.octree.points));
  report.build.seconds += report.build.phases.back().seconds;
  report.bytes = folderBytes(output);
  return report;
}

} // namespace pointrast::io
