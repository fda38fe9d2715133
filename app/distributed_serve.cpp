#include "distributed_serve.h"

#include <algorithm>
#include <cstring>
#include <list>
#include <type_traits>
#include <vector>

#include "base/error.h"
#include "base/progress.h"
#include "distributed.h"
#include "gpu/context.h"
#include "gpu/shared_types.h"
#include "mpi/mpi_job.h"
#include "render/composite.h"
#include "view/scene_view.h"

namespace pointrast::app {

namespace {

// What every rank needs of one of rank 0's draws: the renderer's size, the camera, the render settings
// and the settings the source itself applies (colors, the node cache), with rank 0's colors of a cloud.
struct DrawOrder {
  bool stop = false;
  int32_t status = 0; // stop: the exit status
  uint32_t width = 0, height = 0, eyes = 1;
  Camera camera;
  RenderSettings settings;
  std::optional<DisplayColorMode::Source> colorSource;
  std::optional<ColorRange> colorRange;
  uint64_t gpuMemory = 0;
  std::optional<DisplayColorMode> colors;
};

// The order as bytes, field by field: RenderSettings holds vectors (clip volumes), so it is not copied
// whole.
class OrderWriter {
public:
  template <class T> void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>, "fields are copied as bytes");
    const char* p = reinterpret_cast<const char*>(&value);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  template <class T> void putVector(const std::vector<T>& values) {
    put(uint64_t(values.size()));
    for (const T& v : values)
      put(v);
  }
  std::vector<char> bytes;
};

class OrderReader {
public:
  explicit OrderReader(const std::vector<char>& bytes) : bytes_(bytes) {}
  template <class T> void get(T& value) {
    static_assert(std::is_trivially_copyable_v<T>, "fields are copied as bytes");
    if (at_ + sizeof(T) > bytes_.size()) throw InternalError("a draw order from rank 0 is cut short");
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
  }
  template <class T> void getVector(std::vector<T>& values) {
    uint64_t n = 0;
    get(n);
    if (n > (bytes_.size() - at_) / sizeof(T)) throw InternalError("a draw order from rank 0 is cut short");
    values.resize(n);
    for (T& v : values)
      get(v);
  }

private:
  const std::vector<char>& bytes_;
  size_t at_ = 0;
};

// Every field of a draw, in one order for writing and reading.
template <class Io, class Order> void fields(Io& io, Order& o, bool write) {
  auto f = [&](auto& v) {
    if constexpr (std::is_same_v<Io, OrderWriter>)
      io.put(v);
    else
      io.get(v);
  };
  auto vec = [&](auto& v) {
    if constexpr (std::is_same_v<Io, OrderWriter>)
      io.putVector(v);
    else
      io.getVector(v);
  };
  f(o.stop);
  f(o.status);
  f(o.width);
  f(o.height);
  f(o.eyes);
  f(o.camera);
  RenderSettings& s = o.settings;
  f(s.method);
  f(s.depth);
  f(s.depthScale);
  f(s.background);
  f(s.frames);
  f(s.warmup);
  f(s.captureWords);
  f(s.precision);
  f(s.batchCulling);
  f(s.batchHqsDense);
  f(s.post);
  f(s.minNodePx);
  f(s.pointBudget);
  f(s.foveation);
  f(s.stereo);
  f(s.hqsPass);
  PointFilter& filter = s.filter;
  vec(filter.boxes);
  vec(filter.orientedBoxes);
  uint64_t polygons = filter.polygons.size();
  f(polygons);
  if (!write) filter.polygons.resize(polygons);
  for (ClipPolygon& p : filter.polygons) {
    vec(p.vertices);
    f(p.zMin);
    f(p.zMax);
  }
  f(filter.clipMode);
  f(filter.classes);
  f(filter.returns);
  // std::pair is not trivially copyable: a range goes as whether it is there, then its ends.
  auto range = [&](std::optional<std::pair<double, double>>& r) {
    bool has = r.has_value();
    f(has);
    if (!write && has) r.emplace();
    if (has) {
      f(r->first);
      f(r->second);
    }
  };
  range(filter.intensity);
  range(filter.gpsTime);
  bool ids = filter.sourceIds.has_value();
  f(ids);
  if (ids) {
    if (!write) filter.sourceIds.emplace();
    vec(*filter.sourceIds);
  }
  f(o.colorSource);
  f(o.colorRange);
  f(o.gpuMemory);
  f(o.colors);
}

// Rank 0's order to every rank; the other ranks wait here between draws (without holding a core:
// mpi_job.h). Throws mpi::JobFailed when a rank failed.
DrawOrder exchangeOrder(const DrawOrder* mine) {
  mpi::Job& job = mpi::Job::get();
  OrderWriter writer;
  if (mine) fields(writer, const_cast<DrawOrder&>(*mine), true);
  uint64_t size = writer.bytes.size();
  job.broadcast(&size, sizeof size);
  writer.bytes.resize(size);
  job.broadcast(writer.bytes.data(), size);
  if (mine) return *mine;
  DrawOrder order;
  OrderReader reader(writer.bytes);
  fields(reader, order, false);
  return order;
}

// The counts every rank adds up for a frame, in one all-reduce: ranks that could not draw, ranks with a
// status line, ranks that drew, ranks whose nodes are still arriving (16 bits each: ranks < 65,536).
constexpr int kErrorShift = 48, kStatusShift = 32, kDrewShift = 16;
uint64_t countOf(uint64_t agreed, int shift) {
  return (agreed >> shift) & 0xFFFF;
}

// Every rank's part of one draw: its share into `renderer` (made by `make` on the ranks that follow),
// composited on rank 0 into that renderer, which then holds the frame of all ranks (Renderer::showComposite).
// Returns rank 0's frame statistics with every rank's points and the slowest rank's time; throws InputError
// on rank 0 (after the other ranks returned) when a rank could not draw, naming it.
struct DrawResult {
  FrameStats stats;
  bool changed = false; // some rank's nodes are still arriving
};
template <class Make, class Resolver>
DrawResult drawShare(view::SceneSource& share, const DrawOrder& order, Make&& make, Resolver&& resolverFor,
                     std::string& status) {
  mpi::Job& job = mpi::Job::get();
  view::ViewSettings applied;
  applied.method = order.settings.method;
  applied.colorSource = order.colorSource;
  applied.colorRange = order.colorRange;
  applied.gpuMemory = order.gpuMemory;
  if (auto* cloud = dynamic_cast<view::GpuCloud*>(&share); cloud && order.colors)
    cloud->setColors(order.colorSource, order.colorRange, *order.colors);
  const RenderSettings mine = rankSettings(order.settings);
  Renderer* renderer = nullptr;
  FrameStats stats;
  std::string error;
  // Where the composite reads this rank's words (a collective before any rank can fail its draw).
  const std::span<uint64_t> words = job.compositeBuffer(uint64_t(order.width) * order.eyes * order.height);
  try {
    renderer = &make();
    stats = share.draw(*renderer, order.camera, mine, applied, status);
    if (stats.frames > 0)
      renderer->framebufferWords(words);
    else
      std::fill(words.begin(), words.end(), shared::kEmptyPixel);
  } catch (const InputError& e) {
    error = e.what();
  } catch (const UnsupportedError& e) {
    error = e.what();
  }
  const uint64_t agreed =
      job.sumOf((error.empty() ? 0 : 1ull << kErrorShift) | (status.empty() ? 0 : 1ull << kStatusShift) |
                (stats.frames > 0 ? 1ull << kDrewShift : 0) | (share.changed() ? 1 : 0));
  DrawResult result;
  result.changed = countOf(agreed, 0) > 0;
  // A rank that could not draw (a frame larger than its device holds): no composite; rank 0 says which.
  // A rank's status line (a damaged node) is shown by rank 0 too.
  if (countOf(agreed, kErrorShift) > 0 || countOf(agreed, kStatusShift) > 0) {
    const std::vector<std::string> errors = job.gatherText(error), statuses = job.gatherText(status);
    for (uint32_t r = 1; r < errors.size(); ++r) {
      if (!errors[r].empty() && error.empty()) error = "rank " + std::to_string(r) + ": " + errors[r];
      if (!statuses[r].empty() && status.find(statuses[r]) == std::string::npos)
        status += (status.empty() ? "rank " : "; rank ") + std::to_string(r) + ": " + statuses[r];
    }
    if (countOf(agreed, kErrorShift) > 0) {
      if (job.root()) throw InputError(error);
      return result;
    }
  }
  const uint64_t points = job.sumOf(stats.points);
  const double slowest = job.maxOf(stats.medianMs);
  CompositeStats composite;
  std::vector<uint64_t> ended;
  const std::vector<uint32_t> image =
      compositeWords(resolverFor(*renderer), words, order.camera, order.settings, order.settings.depthScale,
                     composite, &ended);
  if (!job.root()) return result;
  renderer->showComposite(image, ended);
  result.stats = stats;
  result.stats.frames = countOf(agreed, kDrewShift) > 0 ? std::max(stats.frames, 1u) : 0;
  result.stats.points = points;
  result.stats.medianMs = result.stats.minMs = result.stats.maxMs = slowest;
  result.stats.post = composite.post;
  // The level of detail converged when every rank's share did: the page's statistics say so only then.
  if (result.stats.lod && result.changed) result.stats.lod->converged = false;
  return result;
}

class CompositedSource final : public view::SceneSource {
public:
  CompositedSource(gpu::Context& context, std::unique_ptr<view::SceneSource> share, uint64_t points)
      : context_(context), share_(std::move(share)), points_(points) {}
  const std::string& name() const override { return share_->name(); }
  const Bounds& bounds() const override { return share_->bounds(); }
  uint64_t pointCount() const override { return points_; }
  bool streamed() const override { return share_->streamed(); }
  uint64_t bytes() const override { return share_->bytes(); } // rank 0's
  bool changed() const override { return changed_; }
  std::optional<std::string> refuses(Method method) const override { return viewRefusal(method); }
  std::string pointsElsewhere() const override {
    return "under mpirun each rank holds only its share of the points, so points are picked and measured by "
           "pointrast serve on one process";
  }

  FrameStats draw(Renderer& renderer, const Camera& camera, const RenderSettings& rs,
                  const view::ViewSettings& settings, std::string& status) override {
    if (std::optional<std::string> why = viewRefusal(rs.method)) throw InputError(*why);
    DrawOrder order;
    order.width = renderer.width() / renderer.eyes();
    order.height = renderer.height();
    order.eyes = renderer.eyes();
    order.camera = camera;
    order.settings = rs;
    order.colorSource = settings.colorSource;
    order.colorRange = settings.colorRange;
    order.gpuMemory = settings.gpuMemory;
    // A cloud's colors are rank 0's choice (percentile ramps from its share), and int40 depths take rank
    // 0's steps, as render's do.
    if (auto* cloud = dynamic_cast<view::GpuCloud*>(share_.get())) {
      if (std::optional<std::string> why = cloud->setColors(settings.colorSource, settings.colorRange))
        status = *why;
      order.colors = cloud->colors();
      const SceneLayout layout = methodInfo(rs.method).layout;
      if (rs.depth == DepthMode::Int40 && rs.depthScale <= 0 && layout != SceneLayout::Octree) {
        const GpuScene* scenes[] = {&cloud->scene(layout)};
        order.settings.depthScale = int40ScaleOf(scenes, camera);
      }
    }
    exchangeOrder(&order);
    const DrawResult result = drawShare(
        *share_, order, [&]() -> Renderer& { return renderer; },
        [&](Renderer& r) -> CompositeResolver& { return resolverFor(r); }, status);
    changed_ = result.changed;
    return result.stats;
  }

private:
  // The resolve stage's pipelines are made once per frame size: a few sizes stay (the full frame, the
  // smaller one while the camera moves, a screenshot's).
  CompositeResolver& resolverFor(const Renderer& r) {
    const uint64_t key = uint64_t(r.width()) << 32 | uint64_t(r.height()) << 1 | (r.eyes() - 1);
    for (auto it = resolvers_.begin(); it != resolvers_.end(); ++it)
      if (it->first == key) {
        resolvers_.splice(resolvers_.begin(), resolvers_, it);
        return *resolvers_.front().second;
      }
    resolvers_.emplace_front(
        key, std::make_unique<CompositeResolver>(context_, r.width() / r.eyes(), r.height(), r.eyes()));
    if (resolvers_.size() > kKeptSizes) resolvers_.pop_back();
    return *resolvers_.front().second;
  }
  static constexpr size_t kKeptSizes = 3;
  gpu::Context& context_;
  std::unique_ptr<view::SceneSource> share_;
  uint64_t points_;
  bool changed_ = false;
  std::list<std::pair<uint64_t, std::unique_ptr<CompositeResolver>>> resolvers_;
};

} // namespace

std::optional<std::string> viewRefusal(Method method) {
  const MethodInfo& info = methodInfo(method);
  if (hasCanonicalWords(info)) return std::nullopt;
  return std::string(info.name) +
         (info.output == MethodOutput::ColorOnly ? " keeps no depth per pixel" : " blends points") +
         ", so ranks' frames cannot be composited; under mpirun serve draws the closest-point methods "
         "(atomicmin, the batch methods, lod)";
}

std::unique_ptr<view::SceneSource>
compositedSource(gpu::Context& context, std::unique_ptr<view::SceneSource> share, uint64_t points) {
  return std::make_unique<CompositedSource>(context, std::move(share), points);
}

int followDraws(gpu::Context& context, view::SceneSource& share) {
  // The renderers of the last few frame sizes (as rank 0's views keep theirs), most recent first.
  std::list<std::pair<uint64_t, std::unique_ptr<Renderer>>> renderers;
  constexpr size_t kKept = 3;
  for (;;) {
    const DrawOrder order = exchangeOrder(nullptr);
    if (order.stop) return order.status;
    auto make = [&]() -> Renderer& {
      const uint64_t key =
          uint64_t(order.width * order.eyes) << 32 | uint64_t(order.height) << 1 | (order.eyes - 1);
      for (auto it = renderers.begin(); it != renderers.end(); ++it)
        if (it->first == key) {
          renderers.splice(renderers.begin(), renderers, it);
          return *renderers.front().second;
        }
      if (renderers.size() >= kKept) renderers.pop_back(); // its targets go before the new ones
      renderers.emplace_front(key,
                              std::make_unique<Renderer>(context, order.width, order.height, order.eyes));
      return *renderers.front().second;
    };
    std::optional<CompositeResolver> resolver; // its resolve runs on rank 0 only
    std::string status;
    drawShare(
        share, order, make,
        [&](Renderer& r) -> CompositeResolver& {
          return resolver.emplace(context, r.width() / r.eyes(), r.height(), r.eyes());
        },
        status);
  }
}

void stopFollowers(int status) {
  DrawOrder order;
  order.stop = true;
  order.status = status;
  exchangeOrder(&order);
}

int runViewerRanks(std::optional<Method> method, std::optional<uint32_t>& device, bool quiet,
                   const view::ViewSettings& settings, const InputSpec& spec, const SceneOptions& scene,
                   const std::function<int(view::SceneInput&, SourceMaker)>& viewer) {
  mpi::Job& job = mpi::Job::get();
  if (method)
    if (std::optional<std::string> why = viewRefusal(*method)) throw InputError(*why);
  gpu::ContextOptions options;
  options.deviceIndex = device;
  options.announce = !quiet;
  chooseRankDevice(options);
  device = options.deviceIndex;
  if (!quiet) Progress::setEnabled(job.root());
  view::SceneInput input = openSceneShare(spec, scene);
  const view::DrawShare share{job.rank(), job.size()};
  if (!job.root()) {
    gpu::Context context(options);
    announceRanks(context, quiet);
    std::unique_ptr<view::SceneSource> source = view::makeSceneSource(context, input, settings, false, share);
    job.check(); // every rank has its input on its device before rank 0 starts
    return followDraws(context, *source);
  }
  const uint64_t points = input.points;
  const int status = viewer(input, [&job, quiet, share, points](gpu::Context& context, view::SceneInput& in,
                                                                const view::ViewSettings& rootSettings) {
    announceRanks(context, quiet);
    auto mine = view::makeSceneSource(context, in, rootSettings, !quiet, share);
    job.check();
    return compositedSource(context, std::move(mine), points);
  });
  stopFollowers(status);
  return status;
}

} // namespace pointrast::app
