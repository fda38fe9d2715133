// Potree 2.0 octrees (the layout of PotreeConverter 2 and of `pointrast lod`): a folder with
// metadata.json, hierarchy.bin (22-byte node records in chunks of a few levels, proxy records pointing to
// the next chunk) and octree.bin (each node's points, one after another). Read lazily: a hierarchy chunk
// when a node below it is first asked for, a node's points when they are asked for.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "cloud/octree.h"

namespace pointrast::io {

enum class PotreeEncoding {
  Default, // uncompressed records, attribute after attribute within a point
  Brotli,  // per node: Morton-coded positions and attributes compressed with Brotli
};

struct PotreeWriteOptions {
  PotreeEncoding encoding = PotreeEncoding::Default;
  std::string name;        // metadata "name"; empty: the folder's name
  std::string description; // metadata "description"
};

// Writes an octree folder. The folder appears under its final name only at commit(): everything is
// written into a temporary sibling folder first, which the destructor removes if commit() was never
// reached, so an interrupted or failed build leaves nothing half-written behind.
class PotreeWriter {
public:
  // dir must not exist yet (InputError otherwise, naming it). metadata gives the cube, spacing,
  // scale/offset and fields; the point count and tight bounds are taken from what is written.
  PotreeWriter(std::filesystem::path dir, const lod::OctreeMetadata& metadata, const PotreeWriteOptions& options);
  ~PotreeWriter();
  PotreeWriter(const PotreeWriter&) = delete;
  PotreeWriter& operator=(const PotreeWriter&) = delete;

  // Folder the octree is written into until commit() (for temporary files of the caller, which it
  // removes itself before commit()).
  const std::filesystem::path& workingDir() const;

  // Appends one node's points to octree.bin. Every node of the tree is written exactly once (inner
  // nodes included); the order decides the bytes, so a deterministic caller writes in a deterministic
  // order. Not thread-safe. Records' positions are in metadata's scale/offset.
  void writeNode(const lod::NodeKey& key, const PointRecord* records, size_t count);

  // Writes hierarchy.bin and metadata.json and renames the folder into place. Throws InputError (with the
  // folder's name) when a write fails, e.g. a full disk.
  void commit();

  uint64_t bytesWritten() const; // octree.bin so far

private:
  struct State;
  std::unique_ptr<State> state_;
};

// Opens an octree folder (or its metadata.json). Reads metadata.json and the first hierarchy chunk;
// everything else on demand. Throws InputError for a folder that is not a Potree 2.0 octree.
std::unique_ptr<lod::NodeSource> openPotree(const std::filesystem::path& path);

// Whether path is a Potree 2.0 octree folder (or its metadata.json), by its files, without parsing.
bool looksLikePotree(const std::filesystem::path& path);

} // namespace pointrast::io
