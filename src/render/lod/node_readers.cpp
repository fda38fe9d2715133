#include "render/lod/node_readers.h"

#include <chrono>

#include <sys/resource.h>
#include <unistd.h>

#include "base/error.h"
#include "render/lod/selection.h"

namespace pointrast::lod {

NodeReaders::NodeReaders(NodeSource& source, const NodeEncoder& encoder, StagingBlocks& staging,
                         uint32_t threads, int niceness)
    : source_(source), encoder_(encoder), staging_(staging) {
  for (uint32_t t = 0; t < std::max(1u, threads); ++t)
    threads_.emplace_back([this, niceness] {
      // Linux keeps a niceness per thread. Lowering one's own priority needs no privilege; where it is
      // refused anyway the reader runs at the normal priority, which is only slower for the frames.
      if (niceness > 0) (void)setpriority(PRIO_PROCESS, uint32_t(gettid()), niceness);
      run();
    });
}

NodeReaders::~NodeReaders() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  work_.notify_all();
  staging_.stop();
  for (std::thread& t : threads_)
    t.join();
  // Blocks of nodes read and never collected go back with the staging buffer itself.
}

void NodeReaders::want(const std::vector<ReadJob>& jobs) {
  {
    std::lock_guard lock(mutex_);
    queue_.clear();
    for (const ReadJob& job : jobs)
      if (!busy_.count({job.id, job.kind})) queue_.push_back(job);
  }
  work_.notify_all();
}

void NodeReaders::collect(std::vector<ReadPoints>& points, std::vector<ReadChildren>& children) {
  std::lock_guard lock(mutex_);
  if (error_) std::rethrow_exception(error_);
  for (ReadPoints& p : points_) {
    busy_.erase({p.id, ReadJob::Kind::Points});
    points.push_back(std::move(p));
  }
  for (ReadChildren& c : children_) {
    busy_.erase({c.id, ReadJob::Kind::Children});
    children.push_back(std::move(c));
  }
  points_.clear();
  children_.clear();
}

void NodeReaders::wait(double seconds) {
  std::unique_lock lock(mutex_);
  finished_.wait_for(lock, std::chrono::duration<double>(seconds), [&] {
    return error_ || !points_.empty() || !children_.empty() || (queue_.empty() && busy_.empty());
  });
}

size_t NodeReaders::pending() {
  std::lock_guard lock(mutex_);
  size_t inProgress = busy_.size() - points_.size() - children_.size();
  return queue_.size() + inProgress;
}

void NodeReaders::run() {
  for (;;) {
    ReadJob job;
    {
      std::unique_lock lock(mutex_);
      work_.wait(lock, [&] { return stopping_ || (!queue_.empty() && !error_); });
      if (stopping_) return;
      job = std::move(queue_.front());
      queue_.pop_front();
      busy_.insert({job.id, job.kind});
    }
    try {
      perform(job);
    } catch (const InputError&) {
      std::lock_guard lock(mutex_);
      if (!error_) error_ = std::current_exception();
    } catch (const std::exception& e) {
      // Anything else a source throws (a failed allocation, a system error) still names the node.
      std::lock_guard lock(mutex_);
      if (!error_) error_ = std::make_exception_ptr(InputError(describe(job) + ": " + e.what()));
    }
    finished_.notify_all();
  }
}

std::string NodeReaders::describe(const ReadJob& job) const {
  return "node " + job.info.key.potreeName() + " of " + source_.metadata().source;
}

void NodeReaders::perform(const ReadJob& job) {
  if (job.kind == ReadJob::Kind::Children) {
    ReadChildren result{job.id, source_.children(job.info)};
    std::lock_guard lock(mutex_);
    children_.push_back(std::move(result));
    return;
  }
  std::vector<PointRecord> records = source_.readNode(job.info);
  if (records.size() != job.info.pointCount)
    throw InputError(describe(job) + " holds " + std::to_string(records.size()) +
                     " points where its hierarchy says " + std::to_string(job.info.pointCount));
  ReadPoints result;
  result.id = job.id;
  result.points = uint32_t(records.size());
  result.sourceBytes = source_.nodeBytes(job.info);
  std::optional<std::vector<uint32_t>> blocks = staging_.take(uint32_t(pagesOf(records.size())));
  if (!blocks) return; // shutting down
  std::vector<uint8_t*> pages;
  for (uint32_t b : *blocks)
    pages.push_back(staging_.block(b));
  try {
    result.bounds = encoder_.encode(records, pages);
  } catch (...) {
    staging_.give(*blocks);
    throw;
  }
  result.blocks = std::move(*blocks);
  std::lock_guard lock(mutex_);
  points_.push_back(std::move(result));
}

} // namespace pointrast::lod
