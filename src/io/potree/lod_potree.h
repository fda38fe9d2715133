// An octree build written as a Potree 2.0 folder: the builder (lod_builder.h) feeding a PotreeWriter
// (potree.h), nodes encoded on the builder's threads, placed in octree.bin in its order and written there
// by the builder's threads again. The folder appears only
// when everything is written; a failure or an interruption leaves nothing (the writer's temporary folder,
// which also holds the build's temporary chunk files, is removed).
#pragma once

#include <filesystem>
#include <vector>

#include "io/potree/lod_builder.h"
#include "io/potree/potree.h"

namespace pointrast::io {

class PotreeNodeSink final : public lod::NodeSink {
public:
  explicit PotreeNodeSink(PotreeWriter& writer) : writer_(writer) {}
  void writeNode(const lod::NodeKey& key, const PointRecord* records, const uint8_t* tails,
                 size_t count) override;
  std::unique_ptr<lod::PreparedNode> prepare(const lod::NodeKey& key, const PointRecord* records,
                                             const uint8_t* tails, size_t count) const override;
  void writePrepared(const lod::NodeKey& key, lod::PreparedNode* prepared, const PointRecord* records,
                     const uint8_t* tails, size_t count) override;
  void finishPrepared(std::unique_ptr<lod::PreparedNode> prepared) const override;

private:
  PotreeWriter& writer_;
};

struct PotreeBuildReport {
  LodBuildReport build; // its phases end with "commit" (hierarchy.bin, metadata.json, rename)
  uint64_t bytes = 0;   // the folder's files together
};

// Builds the octree of `inputs` into the folder `output` (which must not exist).
PotreeBuildReport buildPotree(const std::vector<std::filesystem::path>& inputs,
                              const std::filesystem::path& output, const LodBuildOptions& options,
                              const PotreeWriteOptions& writeOptions);

} // namespace pointrast::io
