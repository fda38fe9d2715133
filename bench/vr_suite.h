// The `vr2022` suite: the VR frame of "Software Rasterization of 2 Billion Points in Real Time" (Schuetz,
// Kerbl, Wimmer, HPG 2022, section 4.3) on the octree of its 529 M-point laser-scan stand-in: both eyes at
// 2478 x 2740 pixels each (the Valve Index's panels, as the paper renders them), lod-hqs, foveated LOD (100
// px in the fovea up to 300 px at the corners), depth-aware dilation, parallel eyes 6.4 cm apart in the
// scan's metres. Each configuration is measured as one stereo pass (both eyes, each point read once) and as
// two mono renders of the same two eyes (their times added), from views inside and outside the scan.
//
// Rows (VrCase): the VR frame; lod without HQS and dilation (the depth pass and colors alone); the VR frame
// without foveation (what the periphery's coarser nodes save); one eye alone (the paper's "one eye" column).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "bench/runner.h"

namespace pointrast::bench {

struct VrSuiteConfig {
  std::vector<Dataset> datasets;
  uint32_t width = 2478, height = 2740; // each eye's image
  double fovY = 100;                    // vertical field of view of each eye, degrees
  double ipd = 0.064;                   // eye separation, scene units (the stand-ins are in metres)
  double minNodePx = 100;               // in the fovea
  lod::Foveation foveation{true, 0.3, 3.0};
  uint32_t dilate = 1;  // radius: 3 x 3 windows
  uint32_t frames = 20; // timed frames of each measurement; warm-up is warmupFrames(frames)
  std::vector<View> views{View::Closeup, View::Overview};
  uint64_t copyBytes = uint64_t(1) << 30; // the copy bandwidth measured with the run (runner.h)
  int copyRepeats = 10;
  double timeLimitSeconds = 0; // as BenchConfig::timeLimitSeconds
  bool progress = true;
  OctreeProvider octrees;
};

// One configuration of the frame.
struct VrCase {
  std::string name;
  std::string method; // lod or lod-hqs
  bool foveated = true;
  bool dilate = true;
  bool oneEye = false; // the left eye alone (mono only)
};
const std::vector<VrCase>& vrCases();

struct VrResult {
  std::string dataset;
  View view = View::Closeup;
  std::string caseName;
  bool stereo = true; // one stereo pass; false: two mono renders (or one, for the one-eye case)
  std::string status = "ok";
  std::string reason;
  double medianMs = 0;            // the frame: the stereo pass, or the sum of the mono renders' medians
  std::vector<FrameStats> passes; // the stereo pass, or each mono render
  std::string camera;             // the head (between the eyes)
  bool ok() const { return status == "ok"; }
};

struct VrSuiteRun : RunRecord {
  VrSuiteConfig config;
  std::vector<std::pair<std::string, DatasetOctree>> octrees;
  std::vector<VrResult> results;
};

struct VrSuiteCallbacks {
  std::function<void(const std::string&)> onNote;
  std::function<void(const VrSuiteRun&, const VrResult&)> onResult;
};

// The stereo pass of `result`'s configuration against its two mono renders (1 where not measured).
double stereoSpeedup(const VrSuiteRun& run, const VrResult& stereo);

VrSuiteRun runVrSuite(gpu::Context& context, const VrSuiteConfig& config,
                      const VrSuiteCallbacks& callbacks = {});

} // namespace pointrast::bench
