// GLFW's input callbacks, routed to Dear ImGui (when the panel wants the mouse or keyboard) or to the
// session: mouse drags, double-clicks (which GLFW does not report), the wheel, keys.
#pragma once

#include <array>
#include <bitset>
#include <optional>
#include <utility>
#include <vector>

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

  void setPanelVisible(bool visible);
  // The panel's windows' rectangles (x, y, width, height) in the last frame: a press inside one belongs to
  // the panel, whatever ImGui's capture flag said in that frame (the cursor may just have arrived).
  void setPanelRects(std::vector<std::array<float, 4>> rects) { panelRects_ = std::move(rects); }
  // After ImGui::NewFrame: releases of buttons and keys that came in the same frame as their press are
  // handed over now, so that ImGui 1.86, which polls the input state once a frame, sees a quick click or
  // key tap; panelFrameStart, before the next NewFrame, hands over what came after them (the cursor's
  // moves, the modifiers).
  void panelFrameStart();
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
  bool forPanel() const;
  bool panelWantsKeyboard() const;
  void cursor(double x, double y);
  void button(int button, int action, int mods);
  void scroll(double y);
  void key(int key, int action, int mods);
  void character(unsigned int c);

  GLFWwindow* window_;
  Session& session_;
  bool panelVisible_ = true;
  std::vector<std::array<float, 4>> panelRects_;
  bool movedSinceFrame_ = false;
  void applyMods(int mods);

  bool pressedThisFrame_[3] = {false, false, false};
  bool releasePending_[3] = {false, false, false};
  std::bitset<512> keyPressedThisFrame_, keyReleasePending_; // by GLFW key code, as io.KeysDown
  // Modifiers that came after a held release, the cursor's place after a held press; due: for the next frame.
  std::optional<int> modsPending_, modsDue_;
  std::optional<glm::dvec2> cursorPending_, cursorDue_;
  std::vector<unsigned int> charsPending_, charsDue_; // characters typed after held modifiers
  bool arrived_ = true;
  bool dragging_ = false;
  glm::dvec2 cursor_{0};
  double lastClickTime_ = -1;
  glm::dvec2 lastClick_{0};
  double wheel_ = 0;
  bool saveMeasurements_ = false;
  // Input that waits for a frame (see hold in input.cpp), in the order it came.
  struct HeldInput {
    enum Kind { Cursor, Button, Key, Character, Scroll } kind;
    int key, action, mods; // Button: key is the button
    unsigned int codepoint;
    double x, y; // Cursor: window coordinates; Scroll: y is the steps
  };
  bool hold(const HeldInput& e);
  void releaseHeld();
  std::vector<HeldInput> held_;
  int panelPressFrames_ = 0; // frames to build before keyboard input after a panel press is routed
  std::optional<std::pair<glm::dvec2, bool>> toolPress_; // a Ctrl+press: where, and whether Shift was held
};

} // namespace pointrast::view
