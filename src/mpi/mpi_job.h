// One process of a distributed job started by mpirun (docs/mpi.md): sort-last rendering, one rank per
// GPU. Each rank draws its share of the points; closest-point frames composite exactly on rank 0 by a MIN
// over depth << 32 | color words, where the resolve stage then runs once.
//
// The rest of pointrast sees only this interface. In a build without MPI (CMake option POINTRAST_MPI off),
// or in a process mpirun did not start, there is one rank and every collective is the identity.
//
// Failure: every collective first agrees, in one small all-reduce, on whether some rank failed. A rank
// whose work throws calls fail() instead of its next collective: the others learn it there, rank 0 prints
// the one line (naming the rank when not every rank failed), and every rank returns exit code 1 through
// JobFailed; nobody waits on a rank that is gone. Only a rank that fails where this agreement cannot reach
// (inside MPI itself) ends the job with MPI_Abort. The agreement waits without holding a core (it tests for
// the others every millisecond once a first millisecond has passed): the ranks of a browser viewer wait in
// it between frames for as long as nobody moves the camera.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "cloud/cloud.h"

namespace pointrast::mpi {

// Thrown on the ranks that did not fail when another rank did: the line was printed by rank 0 already.
class JobFailed : public std::runtime_error {
public:
  JobFailed() : std::runtime_error("another rank failed") {}
};

// A contiguous range of items.
struct Range {
  uint64_t first = 0, count = 0;
};

// The part of [0, count) that rank `rank` of `ranks` takes: whole blocks of `block` items (the last block
// may be short), split as evenly as possible, lower ranks first. Every rank computes every rank's range
// alike; the ranges tile [0, count).
Range rangeOf(uint64_t count, uint64_t block, uint32_t rank, uint32_t ranks);

class Job {
public:
  // Starts MPI when this build has it and mpirun started the process (its environment says so); call
  // first thing in main. Safe to call in any build.
  static void start(int& argc, char**& argv);
  // Finalizes MPI if started. Call last in main.
  static void finish();
  static Job& get();
  // Whether this build can run distributed (POINTRAST_MPI).
  static bool built();

  bool launched() const { return launched_; } // started by mpirun (of any size)
  bool distributed() const { return size_ > 1; }
  uint32_t rank() const { return rank_; }
  uint32_t size() const { return size_; }
  uint32_t localRank() const { return localRank_; } // among the ranks of this host
  uint32_t localSize() const { return localSize_; }
  bool root() const { return rank_ == 0; }

  // This rank failed with `message`: joins the failure agreement (see above) and returns; the caller
  // then exits 1. Prints nothing itself except on rank 0. Outside a job: prints the line and returns.
  void fail(const std::string& message);
  // The line a rank prints for an error: "pointrast: MESSAGE", with "rank R: " before the message in a
  // distributed job.
  std::string errorLine(const std::string& message) const;

  // --- Collectives: every rank calls them in the same order. Each throws JobFailed when a rank failed.
  void check();                                      // only the agreement (a barrier that carries failure)
  // The command's last collective (a check): a rank failing after it cannot be heard by the others, so
  // fail() then prints its line and ends the job with MPI_Abort.
  void close();
  double maxOf(double value);                        // over all ranks
  uint64_t sumOf(uint64_t value);                    // over all ranks
  std::vector<double> gatherOf(double value);        // on rank 0: one value per rank; elsewhere empty
  std::vector<std::string> gatherText(const std::string& text); // the same for text
  Bounds unionOf(const Bounds& bounds);              // union of every rank's bounds (empty ones ignored)
  void broadcast(void* data, uint64_t bytes);        // rank 0's bytes to every rank
  // The words this rank composites with minToRoot(), `count` of them: when every rank runs on one host,
  // this rank's segment of memory the ranks share (the MIN then runs in place, each rank reducing a stripe
  // of every segment on its threads, and nothing is copied); otherwise a buffer of this process. Kept for
  // the next call of the same count; the contents are this rank's to fill. A collective.
  std::span<uint64_t> compositeBuffer(uint64_t count);
  // Element-wise MIN of every rank's words into rank 0's (the others' are left as they were). Words from
  // compositeBuffer() composite in shared memory on one host; any other words by MPI_Reduce.
  void minToRoot(std::span<uint64_t> words);
  // How minToRoot() composites compositeBuffer()'s words: "shared memory" (one host) or "MPI_Reduce".
  // POINTRAST_MPI_COMPOSITE=reduce forces MPI_Reduce (what several hosts use).
  const char* compositePath() const;
  // Element-wise MIN of every rank's words into every rank's.
  void minToAll(std::span<uint64_t> words);
  // Element-wise SUM of every rank's values into rank 0's.
  void sumToRoot(std::span<uint64_t> values);

private:
  Job() = default;
  void agree(const std::string* failure);
  bool launched_ = false;
  bool started_ = false; // MPI_Init was called
  bool closed_ = false;  // close() was called
  uint32_t rank_ = 0, size_ = 1, localRank_ = 0, localSize_ = 1;
  struct SharedWords; // the shared-memory window of compositeBuffer() (mpi_job.cpp)
  std::shared_ptr<SharedWords> shared_;
  std::vector<uint64_t> ownWords_; // compositeBuffer() without shared memory
};

} // namespace pointrast::mpi
