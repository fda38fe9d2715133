// The worker threads that stream an octree from its source: they read a node's points
// (NodeSource::readNode), encode them into staging blocks (node_encoding.h), or read a node's children
// (NodeSource::children), while frames go on drawing what is resident. The renderer says each frame which
// work it wants, most wanted first; work not started when the wish changes is dropped. A reader's error
// (a damaged node found while streaming) stops all readers and is rethrown by the next collect(), so a
// frame loop ends with that one error instead of waiting for a node that never comes.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "cloud/octree.h"
#include "render/lod/node_encoding.h"
#include "render/lod/staging.h"

namespace pointrast::lod {

struct ReadJob {
  enum class Kind : uint8_t { Points, Children };
  Kind kind = Kind::Points;
  uint32_t id = 0; // the node's id in the renderer's hierarchy
  NodeInfo info;
};

struct ReadPoints {
  uint32_t id = 0;
  uint32_t points = 0;
  std::vector<uint32_t> blocks; // staging blocks holding its pages, in page order
  Bounds bounds;                // tight world bounds its points were quantized in
  uint64_t sourceBytes = 0;     // NodeSource::nodeBytes
};

struct ReadChildren {
  uint32_t id = 0;
  std::vector<NodeInfo> children;
};

class NodeReaders {
public:
  // `niceness` > 0 runs the threads at that lower scheduling priority (nice), so that a viewer's threads
  // that draw and send frames find a core at once while the readers keep every other core busy.
  NodeReaders(NodeSource& source, const NodeEncoder& encoder, StagingBlocks& staging, uint32_t threads,
              int niceness = 0);
  ~NodeReaders(); // stops the threads; work in progress is abandoned
  NodeReaders(const NodeReaders&) = delete;
  NodeReaders& operator=(const NodeReaders&) = delete;

  // Replaces the queue with `jobs`, most wanted first, leaving out those in progress or finished and not
  // collected yet.
  void want(const std::vector<ReadJob>& jobs);
  // Moves finished work out. Rethrows the first error of a reader.
  void collect(std::vector<ReadPoints>& points, std::vector<ReadChildren>& children);
  // Blocks until some work finished (or failed), none is queued or in progress, or `seconds` passed.
  void wait(double seconds);
  // Jobs queued or in progress.
  size_t pending();

private:
  using JobKey = std::pair<uint32_t, ReadJob::Kind>;
  void run();
  void perform(const ReadJob& job);
  std::string describe(const ReadJob& job) const; // "node r07 of cloud/metadata.json", for messages

  NodeSource& source_;
  const NodeEncoder& encoder_;
  StagingBlocks& staging_;
  std::mutex mutex_;
  std::condition_variable work_;     // readers wait for jobs
  std::condition_variable finished_; // wait() waits for results
  std::deque<ReadJob> queue_;
  std::set<JobKey> busy_; // in progress, or finished and not collected
  std::vector<ReadPoints> points_;
  std::vector<ReadChildren> children_;
  std::exception_ptr error_;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

} // namespace pointrast::lod
