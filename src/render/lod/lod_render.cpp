#include "render/lod/lod_render.h"

#include <algorithm>
#include <chrono>

#include "gpu/context.h"
#include "gpu/timer.h"

namespace pointrast::lod {

namespace {

void beginEpilogue(const FrameEpilogue& epilogue, VkCommandBuffer cmd, uint32_t timedFrames) {
  if (epilogue.begin) epilogue.begin(cmd, timedFrames);
}

void recordEpilogue(const FrameEpilogue& epilogue, VkCommandBuffer cmd, uint32_t frame) {
  if (epilogue.record) epilogue.record(cmd, frame);
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void timeOnePass(gpu::Context& context, LodScene& scene, LodPasses& passes, Targets& targets,
                 const LodCamera& cam, const RenderSettings& settings, const FrameEpilogue& epilogue,
                 FrameStats& result) {
  passes.setList(scene.drawList());
  const uint32_t frames = std::max(1u, settings.frames);
  gpu::TimestampPool timestamps(context, frames);
  context.submitAndWait([&](VkCommandBuffer cmd) {
    timestamps.reset(cmd);
    beginEpilogue(epilogue, cmd, frames);
    for (uint32_t w = 0; w < settings.warmup; ++w) {
      passes.recordFrame(cmd, cam, targets, settings);
      recordEpilogue(epilogue, cmd, FrameEpilogue::kUntimed);
    }
    for (uint32_t f = 0; f < frames; ++f) {
      timestamps.begin(cmd, f);
      passes.recordFrame(cmd, cam, targets, settings);
      recordEpilogue(epilogue, cmd, f);
      timestamps.end(cmd, f);
    }
  });
  const std::vector<double> ms = timestamps.milliseconds();
  result.frames = frames;
  result.medianMs = gpu::median(ms);
  result.minMs = *std::min_element(ms.begin(), ms.end());
  result.maxMs = *std::max_element(ms.begin(), ms.end());
}

// Each pass streamed in, then drawn in its own submission (lod-hqs: every pass's depths, then every pass's
// blending, streaming the passes twice). One frame, its time the sum of the submissions'.
void timePasses(gpu::Context& context, LodScene& scene, LodPasses& passes, Targets& targets,
                const LodCamera& cam, const RenderSettings& settings, const FrameEpilogue& epilogue,
                const std::vector<std::vector<uint32_t>>& split, FrameStats& result, double& streamSeconds) {
  // lod-hqs in steps (HqsPass): the depth round, the blend round, or the resolve alone.
  const HqsPass step = passes.hqs() ? settings.hqsPass : HqsPass::Whole;
  std::vector<LodPhase> phases;
  if (!passes.hqs()) phases.push_back(LodPhase::Closest);
  if (passes.hqs() && (step == HqsPass::Whole || step == HqsPass::Depth)) phases.push_back(LodPhase::Depth);
  if (passes.hqs() && (step == HqsPass::Whole || step == HqsPass::Blend)) phases.push_back(LodPhase::Blend);
  const bool finish = step == HqsPass::Whole || step == HqsPass::Resolve;
  if (phases.empty()) { // the resolve of sums set from outside
    gpu::TimestampPool timestamps(context, 1);
    context.submitAndWait([&](VkCommandBuffer cmd) {
      timestamps.reset(cmd);
      beginEpilogue(epilogue, cmd, 1);
      timestamps.begin(cmd, 0);
      passes.recordFinish(cmd, targets, settings);
      recordEpilogue(epilogue, cmd, 0);
      timestamps.end(cmd, 0);
    });
    result.frames = 1;
    result.medianMs = result.minMs = result.maxMs = timestamps.milliseconds()[0];
    return;
  }
  const uint32_t spans = uint32_t(split.size() * phases.size());
  gpu::TimestampPool timestamps(context, spans);
  uint32_t span = 0;
  for (LodPhase phase : phases) {
    uint32_t rank = 0;
    for (const std::vector<uint32_t>& pass : split) {
      const auto start = std::chrono::steady_clock::now();
      scene.makeResident(pass, rank);
      streamSeconds += secondsSince(start);
      rank += uint32_t(pass.size());
      passes.setList(scene.drawList());
      const bool first = span == 0, last = span + 1 == spans;
      context.submitAndWait([&](VkCommandBuffer cmd) {
        if (first) timestamps.reset(cmd);
        if (last) beginEpilogue(epilogue, cmd, 1);
        timestamps.begin(cmd, span);
        if (first) passes.recordBegin(cmd, targets, step);
        passes.recordPass(cmd, cam, targets, settings, phase);
        if (last && finish) {
          passes.recordFinish(cmd, targets, settings);
          recordEpilogue(epilogue, cmd, 0);
        }
        timestamps.end(cmd, span);
      });
      ++span;
    }
  }
  const std::vector<double> ms = timestamps.milliseconds();
  double total = 0;
  for (double m : ms)
    total += m;
  result.frames = 1;
  result.medianMs = result.minMs = result.maxMs = total;
}

} // namespace

LodCamera lodCamera(const LodScene& scene, std::span<const Camera> views, uint32_t width, uint32_t height) {
  const double aspect = double(width) / double(height);
  LodCamera cam;
  cam.viewProj = glm::mat4(viewProjection(views[0], scene.origin(), aspect));
  if (views.size() > 1) cam.rightViewProj = glm::mat4(viewProjection(views[1], scene.origin(), aspect));
  cam.nearW = float(scene.nearW(views[0]));
  return cam;
}

LodView lodView(const RenderSettings& settings) {
  return {settings.minNodePx, settings.pointBudget, settings.foveation};
}

FrameStats renderOctree(gpu::Context& context, LodScene& scene, LodPasses& passes, Targets& targets,
                        std::span<const Camera> views, const RenderSettings& settings,
                        const FrameEpilogue& epilogue) {
  FrameStats result;
  const auto start = std::chrono::steady_clock::now();
  const Selection selection = scene.selectAll(views, targets.eyeWidth(), targets.height, lodView(settings));
  const std::vector<std::vector<uint32_t>> split = scene.splitPasses(selection);
  const LodCamera cam = lodCamera(scene, views, targets.eyeWidth(), targets.height);
  double streamSeconds = 0;
  uint64_t nodes = 0, points = 0, pages = 0;
  if (split.size() <= 1) {
    scene.makeResident(split.empty() ? std::vector<uint32_t>{} : split[0], 0);
    streamSeconds = secondsSince(start);
    timeOnePass(context, scene, passes, targets, cam, settings, epilogue, result);
    nodes = scene.stats().nodesDrawn;
    points = scene.stats().pointsDrawn;
    pages = scene.stats().pagesDrawn;
  } else {
    timePasses(context, scene, passes, targets, cam, settings, epilogue, split, result, streamSeconds);
    for (const std::vector<uint32_t>& pass : split) {
      nodes += pass.size();
      for (uint32_t id : pass) {
        const uint64_t n = scene.hierarchy().node(id).info.pointCount;
        points += n;
        pages += pagesOf(n);
      }
    }
  }
  result.points = selection.points;
  result.batch = passes.readStats();
  LodStats lod = scene.stats();
  lod.nodesDrawn = nodes; // over every pass
  lod.pointsDrawn = points;
  lod.pagesDrawn = pages;
  lod.passes = uint32_t(std::max<size_t>(1, split.size()));
  lod.converged = true;
  lod.changed = true;
  lod.streamSeconds = streamSeconds;
  result.lod = lod;
  return result;
}

FrameStats renderResidentFrame(gpu::Context& context, LodScene& scene, LodPasses& passes, Targets& targets,
                               std::span<const Camera> views, const RenderSettings& settings,
                               const FrameEpilogue& epilogue) {
  FrameStats result;
  const bool changed = scene.update(views, targets.eyeWidth(), targets.height, lodView(settings));
  passes.setList(scene.drawList());
  const LodCamera cam = lodCamera(scene, views, targets.eyeWidth(), targets.height);
  gpu::TimestampPool timestamps(context, 1);
  context.submitAndWait([&](VkCommandBuffer cmd) {
    timestamps.reset(cmd);
    beginEpilogue(epilogue, cmd, 1);
    timestamps.begin(cmd, 0);
    scene.recordUploads(cmd);
    passes.recordFrame(cmd, cam, targets, settings);
    recordEpilogue(epilogue, cmd, 0);
    timestamps.end(cmd, 0);
  });
  scene.uploadsFinished();
  result.frames = 1;
  result.medianMs = result.minMs = result.maxMs = timestamps.milliseconds()[0];
  result.points = scene.stats().pointsDrawn;
  result.batch = passes.readStats();
  LodStats lod = scene.stats();
  lod.passes = 1;
  lod.converged = scene.converged();
  lod.changed = changed;
  result.lod = lod;
  return result;
}

} // namespace pointrast::lod
