// GLFW's input callbacks, routed to Dear ImGui (when the panel wants the mouse or keyboard) or to the
// session: mouse drags, double-clicks (which GLFW does not report), the wheel, keys.
#pragma once

#include <array>
#include <optional>
#include <utility>

#include <glm/glm.hpp>

struct GLFWwindow;
struct ImGuiIO;

namespace pointrast::view {

class Session;

// Two left clicks within this time and distance make a double-click.
constexpr double kDoubleClickSeconds = 0.4;
constexpr double kDoubleClickPixels = 4.0;

// ImGui 1.86 reads keys through io.KeyMap into io.KeysDown, indexed by GLFW key codes here.
void mapImGuiKeys(ImGuiIO& io);

struct WheelInput {
  glm::dvec2 position;
  double steps;
};

class DesktopInput {
public:
  // Installs the callbacks on the window (and its user pointer).
  DesktopInput(GLFWwindow* window, Session& session);

  void setPanelVisible(bool visible) { panelVisible_ = visible; }
  // The panel window's rectangle (x, y, width, height) in the last frame: a press inside it belongs to the
  // panel, whatever ImGui's capture flag said in that frame (the cursor may just have arrived).
  void setPanelRect(const std::array<float, 4>& rect) { panelRect_ = rect; }
  // After ImGui::NewFrame: releases that came in the same frame as their press are handed over now, so
  // that ImGui 1.86, which polls the button state once a frame, sees a quick click as a click.
  void panelFrameDone();
  // Whether any event arrived since the last call (the panel must be redrawn).
  bool takeArrived() { return std::exchange(arrived_, false); }
  // Wheel steps gathered since the last call, at the cursor's last position: the viewer reads the depth
  // under the cursor once for all of them.
  std::optional<WheelInput> takeWheel();
  // Whether Ctrl+S asked to save the measurements since the last call.
  bool takeSaveMeasurements() { return std::exchange(saveMeasurements_, false); }

private:
  static DesktopInput& of(GLFWwindow* window);
  glm::dvec2 toPixels(double x, double y) const;
  bool panelWantsMouse() const;
  bool overPanel() const;
  bool panelWantsKeyboard() const;
  void cursor(double x, double y);
  void button(int button, int action, int mods);
  void scroll(double y);
  void key(int key, int action, int mods);

  GLFWwindow* window_;
  Session& session_;
  bool panelVisible_ = true;
  std::array<float, 4> panelRect_{0, 0, 0, 0};
  bool pressedThisFrame_[3] = {false, false, false};
  bool releasePending_[3] = {false, false, false};
  bool arrived_ = true;
  bool dragging_ = false;
  glm::dvec2 cursor_{0};
  double lastClickTime_ = -1;
  glm::dvec2 lastClick_{0};
  double wheel_ = 0;
  bool saveMeasurements_ = false;
  std::optional<std::pair<glm::dvec2, bool>> toolPress_; // a Ctrl+press: where, and whether Shift was held
};

} // namespace pointrast::view
