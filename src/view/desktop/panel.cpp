#include "view/desktop/panel.h"

#include <algorithm>
#include <cstdio>

#include <imgui.h>

#include "base/progress.h"

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

void statistics(const Session& session, const PanelInfo& info) {
  const Statistics& s = session.statistics();
  ImGui::Text("%s", info.device.c_str());
  ImGui::Text("%s: %s points", info.input.c_str(), humanCount(double(info.points)).c_str());
  ImGui::Text("GPU render  %8.3f ms  (clear + draw + resolve)", s.renderMs);
  ImGui::Text("GPU present %8.3f ms  (image copy + panel)", s.presentMs);
  ImGui::Text("frame (host) %7.2f ms, %llu frames", s.hostMs, static_cast<unsigned long long>(s.frames));
  ImGui::Text("points drawn %s, %s points/s", humanCount(double(s.points)).c_str(),
              humanCount(s.renderMs > 0 ? double(s.points) / (s.renderMs * 1e-3) : 0).c_str());
  if (s.batch)
    ImGui::Text("batches %s of %s rendered, %s points passed early-z",
                humanCount(double(s.batch->batchesRendered)).c_str(),
                humanCount(double(s.batch->batchesProcessed)).c_str(),
                humanCount(double(s.batch->pointsRendered)).c_str());
  ImGui::Text("GPU memory %.1f MiB (scene + targets)", double(s.gpuBytes) / (1 << 20));
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

} // namespace

PanelActions buildPanel(Session& session, const PanelInfo& info, ViewSettings& settings, PanelItems& items) {
  PanelActions actions;
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.85f);
  ImGui::Begin("pointrast", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  methodCombo(info, settings, items);
  backgroundControls(settings, items);
  if (ImGui::CollapsingHeader("Statistics", ImGuiTreeNodeFlags_DefaultOpen)) statistics(session, info);
  if (ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen))
    cameraControls(session, actions, items);
  if (ImGui::CollapsingHeader("Keyframes")) keyframeControls(session, info, actions);
  if (ImGui::CollapsingHeader("Screenshot")) screenshotControls(session, actions);
  ImGui::TextDisabled("drag: orbit  right/middle drag: pan  wheel: zoom\n"
                      "double-click: pivot  WASD QE: fly (Shift: fast)\n"
                      "8 2 5 0 4 6: views  F: frame all  K: keyframe\n"
                      "C: print camera  F12: screenshot  H: hide panel");
  ImVec2 position = ImGui::GetWindowPos(), size = ImGui::GetWindowSize();
  items["panel"] = {position.x, position.y, size.x, size.y};
  ImGui::End();
  return actions;
}

} // namespace pointrast::view
