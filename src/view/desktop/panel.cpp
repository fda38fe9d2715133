#include "view/desktop/panel.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>

#include <imgui.h>

#include "base/progress.h"
#include "cloud/attribute_colors.h"
#include "shared.h"
#include "view/desktop/panel_renderer.h"

namespace pointrast::view {

namespace {

// The background presets, RGBA8 (r | g << 8 | b << 16 | a << 24).
struct Preset {
  const char* label;
  uint32_t rgba;
};
constexpr Preset kBackgrounds[] = {{"Black", 0xFF000000u}, {"White", 0xFFFFFFFFu}, {"Gray", 0xFF404040u}};

void remember(PanelItems& items, const std::string& label) {
  ImVec2 min = ImGui::GetItemRectMin(), max = ImGui::GetItemRectMax();
  items[label] = {min.x, min.y, max.x - min.x, max.y - min.y};
}

// Profile: the line typed or taken from the latest measurement (its vertices' x and y), the strip's width,
// Cut to show the side view in a window of its own, and the exports to the typed file, whose extension the
// button sets (.las, .csv, .png).
void profileControls(Session& session, PanelInfo& info, PanelActions& actions, PanelItems& items) {
  char* text = info.profileLineText.data();
  if (ImGui::Button("From measurement")) {
    const Annotations& all = session.measurements().all();
    for (size_t i = all.items.size(); i-- > 0;) {
      const Annotation& a = all.items[i];
      if (a.points.size() < 2 || (a.kind != AnnotationKind::Distance && a.kind != AnnotationKind::Area))
        continue;
      std::string line;
      char number[64];
      for (const glm::dvec3& p : a.points) {
        std::snprintf(number, sizeof number, "%s%.3f,%.3f", line.empty() ? "" : ",", p.x, p.y);
        line += number;
      }
      if (line.size() < info.profileLineText.size())
        std::snprintf(text, info.profileLineText.size(), "%s", line.c_str());
      break;
    }
  }
  remember(items, "From measurement");
  ImGui::InputText("line", text, info.profileLineText.size());
  remember(items, "line");
  ImGui::InputDouble("width", &info.profileWidth, 0, 0, "%.3f");
  remember(items, "width");
  ImGui::InputTextWithHint("file##profile", "pointrast-profile beside the screenshots",
                           info.profileFileText.data(), info.profileFileText.size());
  remember(items, "profile file");
  if (ImGui::Button("Cut")) actions.profile = true;
  remember(items, "Cut");
  ImGui::BeginDisabled(info.profileImageWidth == 0);
  ImGui::SameLine();
  if (ImGui::Button("Profile LAS")) actions.profileLas = true;
  remember(items, "Profile LAS");
  ImGui::SameLine();
  if (ImGui::Button("Profile CSV")) actions.profileCsv = true;
  remember(items, "Profile CSV");
  ImGui::SameLine();
  if (ImGui::Button("Profile PNG")) actions.profilePng = true;
  remember(items, "Profile PNG");
  ImGui::EndDisabled();
  if (!info.profileStatus.empty()) ImGui::TextWrapped("%s", info.profileStatus.c_str());
}

// The last cut profile in a window of its own, at the picture's size, first shown in the bottom right
// corner of the view, clear of the panel at the top left.
void profileWindow(const PanelInfo& info, PanelItems& items) {
  if (info.profileImageWidth == 0) return;
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowPos(ImVec2(display.x - 8, display.y - 8), ImGuiCond_Appearing, ImVec2(1, 1));
  ImGui::Begin("Profile", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::Image(reinterpret_cast<ImTextureID>(PanelRenderer::kImageId),
               ImVec2(float(info.profileImageWidth), float(info.profileImageHeight)));
  remember(items, "profile image");
  const ImVec2 position = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
  items["profile window"] = {position.x, position.y, size.x, size.y};
  ImGui::End();
}

void methodCombo(const PanelInfo& info, ViewSettings& settings, PanelItems& items) {
  if (ImGui::BeginCombo("Method", methodName(settings.method))) {
    for (Method m : info.methods) {
      bool selected = m == settings.method;
      if (ImGui::Selectable(methodName(m), selected)) settings.method = m;
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", methodInfo(m).help);
      if (selected) ImGui::SetItemDefaultFocus();
    }
    ImGui::EndCombo();
  }
  remember(items, "Method");
}

void depthControls(ViewSettings& settings, PanelItems& items) {
  ImGui::BeginDisabled(!takesInt40(settings.method));
  ImGui::TextUnformatted("Depth");
  ImGui::SameLine();
  if (ImGui::RadioButton("float", settings.depth == DepthMode::Float)) settings.depth = DepthMode::Float;
  remember(items, "float");
  ImGui::SameLine();
  if (ImGui::RadioButton("int40", settings.depth == DepthMode::Int40)) settings.depth = DepthMode::Int40;
  remember(items, "int40");
  ImGui::EndDisabled();
}

void backgroundControls(ViewSettings& settings, PanelItems& items) {
  ImGui::TextUnformatted("Background");
  for (const Preset& p : kBackgrounds) {
    ImGui::SameLine();
    if (ImGui::RadioButton(p.label, settings.background == p.rgba)) settings.background = p.rgba;
    remember(items, p.label);
  }
  float rgb[3] = {float(settings.background & 0xFF) / 255.0f,
                  float((settings.background >> 8) & 0xFF) / 255.0f,
                  float((settings.background >> 16) & 0xFF) / 255.0f};
  if (ImGui::ColorEdit3("Custom", rgb, ImGuiColorEditFlags_NoInputs)) {
    auto byte = [](float v) { return uint32_t(v * 255.0f + 0.5f); };
    settings.background = byte(rgb[0]) | byte(rgb[1]) << 8 | byte(rgb[2]) << 16 | 0xFF000000u;
  }
}

// A "-" and a "+" button after the last item, each remembered as `label -` and `label +`; returns -1, 0
// or 1.
int steppers(const char* label, PanelItems& items) {
  int step = 0;
  ImGui::PushID(label);
  ImGui::SameLine();
  if (ImGui::SmallButton("-")) step = -1;
  remember(items, std::string(label) + " -");
  ImGui::SameLine();
  if (ImGui::SmallButton("+")) step = 1;
  remember(items, std::string(label) + " +");
  ImGui::PopID();
  return step;
}

struct ColorChoice {
  const char* label;
  std::optional<DisplayColorMode::Source> source;
};
constexpr ColorChoice kColors[] = {
    {"Auto", std::nullopt},
    {"RGB", DisplayColorMode::Source::Rgb},
    {"Intensity", DisplayColorMode::Source::Intensity},
    {"Elevation", DisplayColorMode::Source::Elevation},
    {"Classification", DisplayColorMode::Source::Classification},
    {"Return", DisplayColorMode::Source::ReturnNumber},
    {"Source", DisplayColorMode::Source::PointSource},
};

void colorControls(Session& session, ViewSettings& settings, PanelItems& items) {
  ImGui::TextUnformatted("Color");
  for (size_t i = 0; i < std::size(kColors); ++i) {
    if (i != 0 && i != 4) ImGui::SameLine();
    if (i == 4) ImGui::Indent(48);
    if (ImGui::RadioButton(kColors[i].label, settings.colorSource == kColors[i].source)) {
      settings.colorSource = kColors[i].source;
      settings.colorRange.reset();
    }
    remember(items, kColors[i].label);
  }
  ImGui::Unindent(48);
  const bool ramp = settings.colorSource == DisplayColorMode::Source::Intensity ||
                    settings.colorSource == DisplayColorMode::Source::Elevation;
  if (!ramp) return;
  bool custom = settings.colorRange.has_value();
  if (ImGui::Checkbox("Range", &custom)) {
    if (custom) {
      const Bounds& b = session.navigation().bounds();
      settings.colorRange = settings.colorSource == DisplayColorMode::Source::Elevation
                                ? ColorRange{b.min.z, b.max.z}
                                : ColorRange{0.0, 65535.0};
    } else {
      settings.colorRange.reset();
    }
  }
  remember(items, "Range");
  if (!custom) {
    ImGui::SameLine();
    ImGui::TextDisabled("(0.5 %% .. 99.5 %% percentiles)");
    return;
  }
  double range[2] = {settings.colorRange->lo, settings.colorRange->hi};
  ImGui::SameLine();
  ImGui::SetNextItemWidth(220);
  if (ImGui::InputScalarN("lo, hi", ImGuiDataType_Double, range, 2, nullptr, nullptr, "%.6g",
                          ImGuiInputTextFlags_EnterReturnsTrue) &&
      range[0] < range[1])
    settings.colorRange = ColorRange{range[0], range[1]};
}

void pointControls(ViewSettings& settings, PanelItems& items) {
  PostSettings& p = settings.post;
  const float maxSize = float(shared::kMaxPointSize);
  ImGui::SetNextItemWidth(160);
  ImGui::SliderFloat("Point size", &p.pointSize, 1.0f, maxSize, "%.1f px");
  remember(items, "Point size");
  p.pointSize = std::clamp(p.pointSize + float(steppers("Point size", items)), 1.0f, maxSize);
  ImGui::TextUnformatted("Shape");
  ImGui::SameLine();
  if (ImGui::RadioButton("Square", p.shape == PointShape::Square)) p.shape = PointShape::Square;
  remember(items, "Square");
  ImGui::SameLine();
  if (ImGui::RadioButton("Disc", p.shape == PointShape::Disc)) p.shape = PointShape::Disc;
  remember(items, "Disc");
  bool attenuated = p.sizeMode == PointSizeMode::Attenuated;
  ImGui::SameLine();
  if (ImGui::Checkbox("Attenuated", &attenuated))
    p.sizeMode = attenuated ? PointSizeMode::Attenuated : PointSizeMode::Fixed;
  remember(items, "Attenuated");
  if (attenuated) {
    ImGui::SetNextItemWidth(160);
    ImGui::SliderFloat("Largest size", &p.maxPointSize, 1.0f, maxSize, "%.1f px");
    p.maxPointSize = std::clamp(p.maxPointSize, 1.0f, maxSize);
  }
  int dilate = int(p.dilate);
  ImGui::SetNextItemWidth(160);
  ImGui::SliderInt("Dilation", &dilate, 0, int(shared::kMaxDilateRadius), dilate ? "%d px" : "off");
  remember(items, "Dilation");
  dilate += steppers("Dilation", items);
  p.dilate = uint32_t(std::clamp(dilate, 0, int(shared::kMaxDilateRadius)));
  bool edl = p.edlStrength > 0;
  if (ImGui::Checkbox("Eye-dome lighting", &edl)) p.edlStrength = edl ? 1.0f : 0.0f;
  remember(items, "EDL");
  if (edl) {
    ImGui::SetNextItemWidth(160);
    ImGui::SliderFloat("Strength", &p.edlStrength, 0.05f, kMaxEdlStrength, "%.2f");
    p.edlStrength = std::clamp(p.edlStrength, 0.05f, kMaxEdlStrength);
    ImGui::SetNextItemWidth(160);
    ImGui::SliderFloat("Radius", &p.edlRadius, 0.5f, 16.0f, "%.1f px");
    p.edlRadius = std::clamp(p.edlRadius, 0.5f, 16.0f);
  }
}

// Point budgets offered as presets (0: no limit).
struct Budget {
  const char* label;
  uint64_t points;
};
constexpr Budget kBudgets[] = {
    {"none", 0}, {"1M", 1'000'000}, {"3M", 3'000'000}, {"10M", 10'000'000}, {"30M", 30'000'000}};

void lodControls(ViewSettings& settings, PanelItems& items) {
  float minPx = float(settings.minNodePx);
  ImGui::SetNextItemWidth(160);
  if (ImGui::SliderFloat("Min node size", &minPx, 0.0f, 1000.0f, "%.0f px", ImGuiSliderFlags_Logarithmic))
    settings.minNodePx = std::clamp(double(minPx), 0.0, kMaxMinNodePx);
  remember(items, "Min node size");
  ImGui::TextUnformatted("Point budget");
  for (const Budget& b : kBudgets) {
    ImGui::SameLine();
    if (ImGui::RadioButton(b.label, settings.pointBudget == b.points)) settings.pointBudget = b.points;
    remember(items, std::string("Budget ") + b.label);
  }
  // Any other budget: typed in thousands of points.
  uint64_t thousands = settings.pointBudget / 1000, step = 100;
  ImGui::SetNextItemWidth(160);
  if (ImGui::InputScalar("k points", ImGuiDataType_U64, &thousands, &step, nullptr, "%llu",
                         ImGuiInputTextFlags_EnterReturnsTrue))
    settings.pointBudget = std::min(thousands, kMaxPointBudget / 1000) * 1000;
  uint64_t mib = settings.gpuMemory >> 20, mibStep = 256;
  ImGui::SetNextItemWidth(160);
  if (ImGui::InputScalar("GPU memory MiB (0: half)", ImGuiDataType_U64, &mib, &mibStep, nullptr, "%llu",
                         ImGuiInputTextFlags_EnterReturnsTrue))
    settings.gpuMemory = std::min(mib, kMaxGpuMemory >> 20) << 20;
  remember(items, "GPU memory");
}

// Stereo (batch and LOD methods) and foveated LOD (LOD methods), as render --stereo and --foveated.
void stereoControls(ViewSettings& settings, PanelItems& items) {
  ImGui::BeginDisabled(!takesStereo(settings.method));
  ImGui::Checkbox("Stereo", &settings.stereo);
  remember(items, "Stereo");
  ImGui::SameLine();
  ImGui::Checkbox("Cross-eyed", &settings.eyes.crossed);
  remember(items, "Cross-eyed");
  // Scene units; 0: the convergence distance / 30, whatever the units.
  double separation = settings.eyes.separation, step = 0.01;
  ImGui::SetNextItemWidth(160);
  if (ImGui::InputScalar("Eye separation (0: auto)", ImGuiDataType_Double, &separation, &step, nullptr,
                         "%.4g", ImGuiInputTextFlags_EnterReturnsTrue))
    settings.eyes.separation = std::max(0.0, separation);
  remember(items, "Eye separation");
  ImGui::EndDisabled();
  ImGui::BeginDisabled(!takesFoveation(settings.method));
  lod::Foveation& f = settings.foveation;
  ImGui::Checkbox("Foveated", &f.enabled);
  remember(items, "Foveated");
  ImGui::BeginDisabled(!f.enabled);
  float radius = float(f.radius), periphery = float(f.periphery);
  ImGui::SetNextItemWidth(160);
  if (ImGui::SliderFloat("Fovea radius", &radius, 0.0f, 1.0f, "%.2f"))
    f.radius = std::clamp(double(radius), 0.0, 1.0);
  remember(items, "Fovea radius");
  ImGui::SetNextItemWidth(160);
  if (ImGui::SliderFloat("Periphery factor", &periphery, 1.0f, 10.0f, "%.1f"))
    f.periphery = std::clamp(double(periphery), 1.0, kMaxFoveaPeriphery);
  remember(items, "Periphery factor");
  ImGui::EndDisabled();
  ImGui::EndDisabled();
}

std::string mib(uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MiB", double(bytes) / (1 << 20));
  return text;
}

void statistics(const Session& session, const PanelInfo& info) {
  const Statistics& s = session.statistics();
  ImGui::Text("%s", info.device.c_str());
  // The file or folder name keeps the panel narrow; the full path is in the window title and the tooltip.
  const std::filesystem::path input = std::filesystem::path(info.input).lexically_normal();
  const std::string name =
      (input.has_filename() ? input.filename() : input.parent_path().filename()).string();
  ImGui::Text("%s: %s points", name.empty() ? info.input.c_str() : name.c_str(),
              humanCount(double(info.points)).c_str());
  if (ImGui::IsItemHovered() && name != info.input) ImGui::SetTooltip("%s", info.input.c_str());
  // Times and counts in fixed widths that hold every plausible value (up to 10 s, 10^8 frames): the panel
  // keeps its width from frame to frame, however slow the device or busy the machine.
  ImGui::Text("GPU render  %8.3f ms  (clear + draw + resolve)", s.renderMs);
  if (s.post)
    ImGui::Text("  resolve stage: splat %8.3f, dilate %8.3f, compose %8.3f ms", s.post->splatMs,
                s.post->dilateMs, s.post->composeMs);
  ImGui::Text("GPU present %8.3f ms  (image copy + panel)", s.presentMs);
  ImGui::Text("frame (host) %8.2f ms, %8llu frames", s.hostMs, static_cast<unsigned long long>(s.frames));
  ImGui::Text("points drawn %8s, %8s points/s", humanCount(double(s.points)).c_str(),
              humanCount(s.renderMs > 0 ? double(s.points) / (s.renderMs * 1e-3) : 0).c_str());
  if (s.batch && !s.lod)
    ImGui::Text("batches %8s of %8s rendered, %8s points passed early-z",
                humanCount(double(s.batch->batchesRendered)).c_str(),
                humanCount(double(s.batch->batchesProcessed)).c_str(),
                humanCount(double(s.batch->pointsRendered)).c_str());
  if (s.lod) {
    const lod::LodStats& l = *s.lod;
    ImGui::Text("nodes drawn %s of %s selected (%s points)%s", humanCount(double(l.nodesDrawn)).c_str(),
                humanCount(double(l.nodesSelected)).c_str(), humanCount(double(l.pointsDrawn)).c_str(),
                l.budgetReached ? ", budget reached" : "");
    ImGui::Text("nodes loaded %s, evicted %s, %s passes", humanCount(double(l.nodesLoaded)).c_str(),
                humanCount(double(l.nodesEvicted)).c_str(), std::to_string(l.passes).c_str());
    ImGui::Text("streamed %.1f MB/s, %s in all", s.streamedBytesPerSecond * 1e-6,
                mib(l.bytesStreamed).c_str());
    ImGui::Text("node cache %s of %s", mib(l.residentBytes).c_str(), mib(l.cacheBytes).c_str());
    if (l.converged)
      ImGui::TextColored(ImVec4(0.5f, 1.0f, 0.5f, 1.0f), "converged");
    else
      ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "refining");
  }
  ImGui::Text("GPU memory %s (scene + targets)", mib(s.gpuBytes).c_str());
  if (!s.status.empty()) ImGui::TextWrapped("%s", s.status.c_str());
}

void cameraControls(Session& session, PanelActions& actions, PanelItems& items) {
  const Camera& c = session.camera();
  ImGui::Text("eye    %.3f, %.3f, %.3f", c.eye.x, c.eye.y, c.eye.z);
  ImGui::Text("target %.3f, %.3f, %.3f", c.target.x, c.target.y, c.target.z);
  ImGui::Text("pivot  %.3f, %.3f, %.3f", session.pivot().x, session.pivot().y, session.pivot().z);
  if (ImGui::Button("Frame all (F)")) actions.frameAll = true;
  remember(items, "Frame all");
  const StandardView views[] = {StandardView::Top,   StandardView::Front, StandardView::Left,
                                StandardView::Right, StandardView::Back,  StandardView::Iso};
  for (StandardView v : views) {
    ImGui::SameLine();
    if (ImGui::SmallButton(standardViewName(v))) actions.view = v;
  }
}

void keyframeControls(Session& session, const PanelInfo& info, PanelActions& actions) {
  const CameraPath& path = session.path();
  ImGui::Text("%zu keyframes, %.1f s -> %s", path.keyframes().size(), path.duration(), info.pathFile.c_str());
  float seconds = float(session.options().keyframeSeconds);
  ImGui::SetNextItemWidth(120);
  if (ImGui::DragFloat("s between keyframes", &seconds, 0.05f, 0.1f, 60.0f, "%.2f"))
    session.options().keyframeSeconds = std::max(0.1, double(seconds));
  if (ImGui::Button("Add keyframe (K)")) actions.addKeyframe = true;
  ImGui::SameLine();
  if (ImGui::Button("Clear")) actions.clearKeyframes = true;
}

void screenshotControls(Session& session, PanelActions& actions) {
  ImGui::TextUnformatted("Supersample");
  for (uint32_t factor : {1u, 2u, 4u}) {
    ImGui::SameLine();
    char label[8];
    std::snprintf(label, sizeof label, "%ux", factor);
    if (ImGui::RadioButton(label, session.options().supersample == factor))
      session.options().supersample = factor;
  }
  if (ImGui::Button("Screenshot (F12)")) actions.screenshot = true;
}

// Pick and measure: the last pick's attributes, the kind Ctrl+Shift+click measures, the measurements with
// their values, Delete and Save.
void toolControls(Session& session, const PanelInfo& info, PanelActions& actions) {
  ImGui::TextUnformatted("Ctrl+click: pick  Ctrl+Shift+click: measure");
  ImGui::TextUnformatted("Ctrl+drag a vertex: move it");
  if (!info.picked.empty()) ImGui::TextUnformatted(info.picked.c_str());
  MeasureTool& tool = session.measurements();
  const std::pair<AnnotationKind, const char*> kinds[] = {{AnnotationKind::Distance, "distance"},
                                                          {AnnotationKind::Height, "height"},
                                                          {AnnotationKind::Area, "area"}};
  for (const auto& [kind, name] : kinds) {
    ImGui::SameLine();
    if (ImGui::RadioButton(name, tool.measureKind == kind)) {
      tool.measureKind = kind;
      tool.finish();
    }
  }
  const Annotations& all = tool.all();
  for (size_t i = 0; i < all.items.size(); ++i) {
    const Annotation& a = all.items[i];
    ImGui::PushID(int(i));
    if (annotationProblem(a).empty()) {
      const Measurement m = measure(a);
      const double value = a.kind == AnnotationKind::Height ? m.dz
                           : a.kind == AnnotationKind::Area ? m.area
                                                            : m.length;
      ImGui::Text("%s %s", annotationKindName(a.kind), formatLength(value, all.unit).c_str());
    } else {
      ImGui::Text("%s: %zu point(s)", annotationKindName(a.kind), a.points.size());
    }
    ImGui::SameLine();
    if (ImGui::SmallButton("delete")) actions.deleteMeasurement = i;
    ImGui::PopID();
  }
  if (ImGui::Button("Finish")) tool.finish();
  ImGui::SameLine();
  ImGui::BeginDisabled(info.annotationsFile.empty());
  if (ImGui::Button("Save (Ctrl+S)")) actions.saveMeasurements = true;
  ImGui::EndDisabled();
  if (info.annotationsFile.empty()) ImGui::TextDisabled("--annotations FILE to save");
}

// Clip and export: a box typed as six numbers or taken from the view (around the pivot, as wide as the view
// there, the cloud's height), the clip mode, Apply and Clear (the frame's clip volume), and Export LAS of
// the points the applied box keeps, through convert's filter path.
void clipControls(Session& session, PanelInfo& info, ViewSettings& settings, PanelActions& actions,
                  PanelItems& items) {
  char* text = info.clipBoxText.data();
  if (ImGui::Button("From view")) {
    const Camera& c = session.camera();
    const glm::dvec3 p = session.pivot();
    const double half = glm::length(c.eye - p) * std::tan(glm::radians(c.fovY) / 2);
    const Bounds& b = session.navigation().bounds();
    std::snprintf(text, info.clipBoxText.size(), "%.3f,%.3f,%.3f,%.3f,%.3f,%.3f", p.x - half, p.y - half,
                  b.min.z, p.x + half, p.y + half, b.max.z);
  }
  remember(items, "From view");
  ImGui::InputText("box", text, info.clipBoxText.size());
  remember(items, "box");
  if (ImGui::RadioButton("inside", settings.filter.clipMode == ClipMode::Inside))
    settings.filter.clipMode = ClipMode::Inside;
  remember(items, "inside");
  ImGui::SameLine();
  if (ImGui::RadioButton("outside", settings.filter.clipMode == ClipMode::Outside))
    settings.filter.clipMode = ClipMode::Outside;
  remember(items, "outside");
  if (ImGui::Button("Apply")) {
    double v[6];
    ClipBox box;
    if (std::sscanf(text, "%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5]) == 6) {
      box.min = {v[0], v[1], v[2]};
      box.max = {v[3], v[4], v[5]};
      if (box.min.x <= box.max.x && box.min.y <= box.max.y && box.min.z <= box.max.z)
        settings.filter.boxes = {box};
      else
        info.exported = "the box is the min corner, then the max corner";
    } else {
      info.exported = "the box takes six numbers: x0,y0,z0,x1,y1,z1";
    }
  }
  remember(items, "Apply");
  ImGui::SameLine();
  if (ImGui::Button("Clear")) settings.filter.boxes.clear();
  remember(items, "Clear");
  ImGui::SameLine();
  ImGui::BeginDisabled(settings.filter.boxes.empty());
  if (ImGui::Button("Export LAS")) actions.exportLas = true;
  remember(items, "Export LAS");
  ImGui::EndDisabled();
  if (!info.exported.empty()) ImGui::TextUnformatted(info.exported.c_str());
}

} // namespace

PanelActions buildPanel(Session& session, PanelInfo& info, ViewSettings& settings, PanelItems& items) {
  PanelActions actions;
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.85f);
  // The panel stays behind the windows it opens (the Profile picture): a click on its buttons, or a long
  // input path that widens it, must not hide the picture they overlap.
  ImGui::Begin("pointrast", nullptr,
               ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoBringToFrontOnFocus);
  const ViewSettings before = settings;
  methodCombo(info, settings, items);
  depthControls(settings, items);
  backgroundControls(settings, items);
  const bool lookOpen = ImGui::CollapsingHeader("Look", ImGuiTreeNodeFlags_DefaultOpen);
  remember(items, "Look");
  if (lookOpen) {
    colorControls(session, settings, items);
    ImGui::BeginDisabled(!takesPost(settings.method));
    pointControls(settings, items);
    ImGui::EndDisabled();
    if (!takesPost(settings.method))
      ImGui::TextDisabled("%s keeps no depth per pixel: no point size, dilation or EDL",
                          methodName(settings.method));
  }
  if (ImGui::CollapsingHeader("Level of detail", ImGuiTreeNodeFlags_DefaultOpen)) {
    ImGui::BeginDisabled(methodInfo(settings.method).layout != SceneLayout::Octree);
    lodControls(settings, items);
    ImGui::EndDisabled();
  }
  const bool stereoOpen = ImGui::CollapsingHeader("Stereo and foveation", ImGuiTreeNodeFlags_DefaultOpen);
  remember(items, "Stereo and foveation");
  if (stereoOpen) stereoControls(settings, items);
  // A value render would refuse (a slider typed past its end with Ctrl+click) keeps the last good settings.
  try {
    validateSettings(settings);
  } catch (const std::exception&) {
    settings = before;
  }
  if (ImGui::CollapsingHeader("Statistics", ImGuiTreeNodeFlags_DefaultOpen)) statistics(session, info);
  if (ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen))
    cameraControls(session, actions, items);
  if (ImGui::CollapsingHeader("Keyframes")) keyframeControls(session, info, actions);
  if (ImGui::CollapsingHeader("Screenshot")) screenshotControls(session, actions);
  if (ImGui::CollapsingHeader("Pick and measure")) toolControls(session, info, actions);
  const bool clipOpen = ImGui::CollapsingHeader("Clip and export");
  remember(items, "Clip and export");
  if (clipOpen) clipControls(session, info, settings, actions, items);
  const bool profileOpen = ImGui::CollapsingHeader("Profile");
  remember(items, "Profile");
  if (profileOpen) profileControls(session, info, actions, items);
  ImGui::TextDisabled("drag: orbit  right/middle drag: pan  wheel: zoom\n"
                      "double-click: pivot  WASD QE: fly (Shift: fast)\n"
                      "8 2 5 0 4 6: views  F: frame all  K: keyframe\n"
                      "C: print as render options  F12: screenshot  H: hide panel");
  ImVec2 position = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
  items["panel"] = {position.x, position.y, size.x, size.y};
  ImGui::End();
  profileWindow(info, items);
  return actions;
}

} // namespace pointrast::view
