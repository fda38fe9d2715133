// Reports of the LOD methods: their statistics as JSON (render --json and the bench), the LOD half of the
// 2022 paper's Table 2 and the octrees' builds in the point suites' Markdown report.
#pragma once

#include <ostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/report.h"
#include "bench/runner.h"
#include "render/lod/lod_stats.h"

namespace pointrast::bench {

using report::lodStatsJson;
// The octrees' table (data set, points, bytes, build time, reused, phases) for a Markdown report.
void markdownOctrees(std::ostream& md, const std::vector<std::pair<std::string, DatasetOctree>>& octrees);

nlohmann::json octreesJson(const std::vector<std::pair<std::string, DatasetOctree>>& octrees);

// The LOD rows of a run: per data set, view and LOD method, the nodes and points the CPU selected, what
// the GPU processed and rendered, and the speed-up over batch-prefetch from the same camera; then the
// octrees and their builds. Nothing when the run has no LOD result.
void markdownLodStatistics(std::ostream& md, const BenchRun& run);

} // namespace pointrast::bench

namespace pointrast::bench {

struct LodSuiteRun;
struct LodStreamResult;

using report::percentile;

// The lod suite's reports: the run as JSON (every frame of the streaming runs included), a Markdown report
// (render time against the point budget and --min-node-px, the streaming runs against the targets: every
// frame of the flight within 1/60 s, each jump converged within 30 frames) and an SVG chart of the sweeps.
nlohmann::json lodSuiteJson(const LodSuiteRun& run, const ReportInfo& info);
nlohmann::json lodStreamJson(const LodStreamResult& stream);
std::string lodSuiteMarkdown(const LodSuiteRun& run, const ReportInfo& info);
std::string lodSuiteSvg(const LodSuiteRun& run, const ReportInfo& info);
WrittenFiles writeLodSuiteReports(const LodSuiteRun& run, const ReportInfo& info,
                                  const std::filesystem::path& dir);

} // namespace pointrast::bench
