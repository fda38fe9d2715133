#include "mpi/mpi_job.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string_view>
#include <thread>

#include "base/parallel.h"
#include "base/text.h"

#if POINTRAST_HAVE_MPI
// The C interface only: Open MPI's deprecated C++ bindings would need libmpi_cxx.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace pointrast::mpi {

Range rangeOf(uint64_t count, uint64_t block, uint32_t rank, uint32_t ranks) {
  assert(block > 0 && ranks > 0 && rank < ranks && "a rank of the job and a block of items");
  const uint64_t blocks = (count + block - 1) / block;
  const uint64_t base = blocks / ranks, extra = blocks % ranks;
  const uint64_t firstBlock = rank * base + std::min<uint64_t>(rank, extra);
  const uint64_t ownBlocks = base + (rank < extra ? 1 : 0);
  const uint64_t first = std::min(count, firstBlock * block);
  return {first, std::min(count, (firstBlock + ownBlocks) * block) - first};
}

bool Job::built() {
  return POINTRAST_HAVE_MPI != 0;
}

Job& Job::get() {
  static Job job;
  return job;
}

std::string Job::errorLine(const std::string& message) const {
  return "pointrast: " + (distributed() ? "rank " + std::to_string(rank_) + ": " : std::string()) +
         printableLine(message);
}

#if POINTRAST_HAVE_MPI

namespace {

// Open MPI's launcher sets OMPI_COMM_WORLD_SIZE; PMIx and PMI launchers (srun, other MPIs) set theirs.
bool startedByLauncher() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (const char* value = std::getenv(name); value && *value) return true;
  return false;
}

// MPI counts are int: large arrays go in slices of 2^28 elements.
constexpr uint64_t kSlice = uint64_t(1) << 28;

// Waits for a request without holding a core: MPI implementations wait by polling, and the ranks of a
// browser viewer wait between frames for as long as nobody moves the camera. The first millisecond polls
// (a collective between frames of a render answers within it); after that a test every millisecond.
void waitSparingly(MPI_Request& request) {
  const auto start = std::chrono::steady_clock::now();
  int done = 0;
  for (;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    if (std::chrono::steady_clock::now() - start > std::chrono::milliseconds(1))
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

} // namespace

void Job::start(int& argc, char**& argv) {
  Job& job = get();
  if (job.started_ || !startedByLauncher()) return;
  // The browser viewer's rank 0 calls MPI from its render thread and, once that thread ended, from the
  // main thread: never two threads at once.
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided);
  job.started_ = job.launched_ = true;
  int rank = 0, size = 1, localRank = 0, localSize = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  MPI_Comm local;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &local);
  MPI_Comm_rank(local, &localRank);
  MPI_Comm_size(local, &localSize);
  MPI_Comm_free(&local);
  job.rank_ = uint32_t(rank);
  job.size_ = uint32_t(size);
  job.localRank_ = uint32_t(localRank);
  job.localSize_ = uint32_t(localSize);
  // The ranks of one host share its cores: each sizes its parallel loops and readers to its part.
  setThreadShares(job.localSize_);
}

void Job::finish() {
  Job& job = get();
  if (!job.started_) return;
  job.shared_.reset(); // its window goes before MPI does
  job.started_ = false;
  MPI_Finalize();
}

void Job::agree(const std::string* failure) {
  if (!started_) {
    if (failure) std::fprintf(stderr, "%s\n", errorLine(*failure).c_str());
    return;
  }
  const int mine = failure ? 1 : 0;
  int failed = 0;
  MPI_Request request;
  MPI_Iallreduce(&mine, &failed, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD, &request);
  waitSparingly(request);
  if (failed == 0) return;
  // The lowest failing rank's message goes to rank 0, which prints it once for the job.
  const int candidate = failure ? int(rank_) : int(size_);
  int first = 0;
  MPI_Allreduce(&candidate, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  uint64_t length = failure && int(rank_) == first ? failure->size() : 0;
  MPI_Bcast(&length, 1, MPI_UINT64_T, first, MPI_COMM_WORLD);
  std::string text(length, '\0');
  if (int(rank_) == first) text = *failure;
  if (length) MPI_Bcast(text.data(), int(length), MPI_CHAR, first, MPI_COMM_WORLD);
  if (rank_ == 0) {
    const std::string where = failed == int(size_) || size_ == 1 ? "" : "rank " + std::to_string(first) + ": ";
    std::fprintf(stderr, "pointrast: %s%s\n", where.c_str(), printableLine(text).c_str());
    std::fflush(stderr);
  }
  if (!failure) throw JobFailed();
}

void Job::fail(const std::string& message) {
  if (!closed_) {
    agree(&message);
    return;
  }
  std::fprintf(stderr, "%s\n", errorLine(message).c_str());
  std::fflush(stderr);
  MPI_Abort(MPI_COMM_WORLD, 1);
}

void Job::check() {
  agree(nullptr);
}

void Job::close() {
  check();
  closed_ = true;
}

double Job::maxOf(double value) {
  check();
  if (!started_) return value;
  double result = value;
  MPI_Allreduce(&value, &result, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return result;
}

uint64_t Job::sumOf(uint64_t value) {
  check();
  if (!started_) return value;
  uint64_t result = value;
  MPI_Allreduce(&value, &result, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
  return result;
}

std::vector<double> Job::gatherOf(double value) {
  check();
  if (!started_) return {value};
  std::vector<double> all(rank_ == 0 ? size_ : 0);
  MPI_Gather(&value, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  return all;
}

std::vector<std::string> Job::gatherText(const std::string& text) {
  check();
  if (!started_) return {text};
  const int length = int(std::min<size_t>(text.size(), 1u << 20));
  std::vector<int> lengths(rank_ == 0 ? size_ : 0), offsets(lengths.size());
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  int total = 0;
  for (size_t r = 0; r < lengths.size(); ++r) {
    offsets[r] = total;
    total += lengths[r];
  }
  std::string joined(size_t(total), '\0');
  MPI_Gatherv(text.data(), length, MPI_CHAR, joined.data(), lengths.data(), offsets.data(), MPI_CHAR, 0,
              MPI_COMM_WORLD);
  std::vector<std::string> all;
  for (size_t r = 0; r < lengths.size(); ++r)
    all.push_back(joined.substr(size_t(offsets[r]), size_t(lengths[r])));
  return all;
}

Bounds Job::unionOf(const Bounds& bounds) {
  check();
  if (!started_) return bounds;
  // Empty bounds are +inf..-inf, which MIN and MAX ignore by themselves.
  double lo[3] = {bounds.min.x, bounds.min.y, bounds.min.z}, hi[3] = {bounds.max.x, bounds.max.y, bounds.max.z};
  double allLo[3], allHi[3];
  MPI_Allreduce(lo, allLo, 3, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(hi, allHi, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  Bounds result;
  result.min = {allLo[0], allLo[1], allLo[2]};
  result.max = {allHi[0], allHi[1], allHi[2]};
  return result;
}

void Job::broadcast(void* data, uint64_t bytes) {
  check();
  if (!started_) return;
  for (uint64_t at = 0; at < bytes; at += kSlice)
    MPI_Bcast(static_cast<char*>(data) + at, int(std::min(kSlice, bytes - at)), MPI_BYTE, 0, MPI_COMM_WORLD);
}

// One window of memory the ranks of one host share: a segment of `count` words per rank, rank order.
struct Job::SharedWords {
  MPI_Win window = MPI_WIN_NULL;
  uint64_t count = 0;
  std::vector<uint64_t*> segments; // every rank's, mapped into this process
  ~SharedWords() {
    if (window != MPI_WIN_NULL) MPI_Win_free(&window);
  }
};

namespace {

bool compositeInSharedMemory(uint32_t size, uint32_t localSize) {
  const char* forced = std::getenv("POINTRAST_MPI_COMPOSITE");
  if (forced && std::string_view(forced) == "reduce") return false;
  return size > 1 && localSize == size;
}

} // namespace

std::span<uint64_t> Job::compositeBuffer(uint64_t count) {
  check();
  if (!started_ || !compositeInSharedMemory(size_, localSize_)) {
    ownWords_.resize(count);
    return ownWords_;
  }
  if (!shared_ || shared_->count != count) {
    shared_.reset(); // every rank frees the old window before the new one (collectives, in one order)
    auto words = std::make_shared<SharedWords>();
    words->count = count;
    void* base = nullptr;
    MPI_Win_allocate_shared(MPI_Aint(count * 8), 8, MPI_INFO_NULL, MPI_COMM_WORLD, &base, &words->window);
    for (uint32_t r = 0; r < size_; ++r) {
      MPI_Aint bytes = 0;
      int unit = 0;
      void* segment = nullptr;
      MPI_Win_shared_query(words->window, int(r), &bytes, &unit, &segment);
      words->segments.push_back(static_cast<uint64_t*>(segment));
    }
    shared_ = std::move(words);
  }
  return {shared_->segments[rank_], count};
}

const char* Job::compositePath() const {
  return started_ && compositeInSharedMemory(size_, localSize_) ? "shared memory" : "MPI_Reduce";
}

void Job::minToRoot(std::span<uint64_t> words) {
  check();
  if (!started_) return;
  if (shared_ && words.data() == shared_->segments[rank_] && words.size() == shared_->count) {
    // Every rank's words are in; each reduces its stripe of the pixels over every segment into rank 0's.
    MPI_Win_fence(0, shared_->window);
    const Range stripe = rangeOf(words.size(), 1, rank_, size_);
    const std::vector<uint64_t*>& segments = shared_->segments;
    parallelBlocks(stripe.count, uint64_t(1) << 16, [&](uint64_t, uint64_t begin, uint64_t end) {
      uint64_t* out = segments[0] + stripe.first;
      for (uint32_t r = 1; r < segments.size(); ++r) {
        const uint64_t* in = segments[r] + stripe.first;
        for (uint64_t i = begin; i < end; ++i)
          out[i] = std::min(out[i], in[i]);
      }
    });
    MPI_Win_fence(0, shared_->window); // rank 0 reads every stripe after this
    return;
  }
  for (uint64_t at = 0; at < words.size(); at += kSlice) {
    const int n = int(std::min<uint64_t>(kSlice, words.size() - at));
    if (rank_ == 0)
      MPI_Reduce(MPI_IN_PLACE, words.data() + at, n, MPI_UINT64_T, MPI_MIN, 0, MPI_COMM_WORLD);
    else
      MPI_Reduce(words.data() + at, nullptr, n, MPI_UINT64_T, MPI_MIN, 0, MPI_COMM_WORLD);
  }
}

void Job::minToAll(std::span<uint64_t> words) {
  check();
  if (!started_) return;
  for (uint64_t at = 0; at < words.size(); at += kSlice) {
    const int n = int(std::min<uint64_t>(kSlice, words.size() - at));
    MPI_Allreduce(MPI_IN_PLACE, words.data() + at, n, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD);
  }
}

void Job::sumToRoot(std::span<uint64_t> values) {
  check();
  if (!started_) return;
  for (uint64_t at = 0; at < values.size(); at += kSlice) {
    const int n = int(std::min<uint64_t>(kSlice, values.size() - at));
    if (rank_ == 0)
      MPI_Reduce(MPI_IN_PLACE, values.data() + at, n, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
    else
      MPI_Reduce(values.data() + at, nullptr, n, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
  }
}

#else // a build without MPI: one rank, every collective the identity

void Job::start(int&, char**&) {}
void Job::finish() {}

void Job::agree(const std::string* failure) {
  if (failure) std::fprintf(stderr, "%s\n", errorLine(*failure).c_str());
}
void Job::fail(const std::string& message) {
  agree(&message);
}
void Job::check() {}
void Job::close() {}
double Job::maxOf(double value) {
  return value;
}
uint64_t Job::sumOf(uint64_t value) {
  return value;
}
std::vector<double> Job::gatherOf(double value) {
  return {value};
}
std::vector<std::string> Job::gatherText(const std::string& text) {
  return {text};
}
Bounds Job::unionOf(const Bounds& bounds) {
  return bounds;
}
void Job::broadcast(void*, uint64_t) {}
std::span<uint64_t> Job::compositeBuffer(uint64_t count) {
  ownWords_.resize(count);
  return ownWords_;
}
const char* Job::compositePath() const {
  return "none";
}
void Job::minToRoot(std::span<uint64_t>) {}
void Job::minToAll(std::span<uint64_t>) {}
void Job::sumToRoot(std::span<uint64_t>) {}

#endif

} // namespace pointrast::mpi
