#include "view/desktop/input.h"

#include <utility>

#include <imgui.h>

#include "view/desktop/glfw_api.h"
#include "view/session.h"

namespace pointrast::view {

namespace {

std::optional<Key> sessionKey(int key) {
  switch (key) {
  case GLFW_KEY_W:
    return Key::Forward;
  case GLFW_KEY_S:
    return Key::Back;
  case GLFW_KEY_A:
    return Key::Left;
  case GLFW_KEY_D:
    return Key::Right;
  case GLFW_KEY_Q:
    return Key::Down;
  case GLFW_KEY_E:
    return Key::Up;
  case GLFW_KEY_F:
    return Key::FrameAll;
  case GLFW_KEY_K:
    return Key::Keyframe;
  case GLFW_KEY_H:
    return Key::TogglePanel;
  case GLFW_KEY_C:
    return Key::PrintCamera;
  case GLFW_KEY_F12:
    return Key::Screenshot;
  case GLFW_KEY_ESCAPE:
    return Key::Quit;
  // CloudCompare's view keys, on the keypad or the number row.
  case GLFW_KEY_8:
  case GLFW_KEY_KP_8:
    return Key::ViewTop;
  case GLFW_KEY_2:
  case GLFW_KEY_KP_2:
    return Key::ViewBottom;
  case GLFW_KEY_5:
  case GLFW_KEY_KP_5:
    return Key::ViewFront;
  case GLFW_KEY_0:
  case GLFW_KEY_KP_0:
    return Key::ViewBack;
  case GLFW_KEY_4:
  case GLFW_KEY_KP_4:
    return Key::ViewLeft;
  case GLFW_KEY_6:
  case GLFW_KEY_KP_6:
    return Key::ViewRight;
  case GLFW_KEY_1:
  case GLFW_KEY_KP_1:
    return Key::ViewIso;
  default:
    return std::nullopt;
  }
}

} // namespace

void mapImGuiKeys(ImGuiIO& io) {
  const std::pair<ImGuiKey, int> keys[] = {{ImGuiKey_Tab, GLFW_KEY_TAB},
                                           {ImGuiKey_LeftArrow, GLFW_KEY_LEFT},
                                           {ImGuiKey_RightArrow, GLFW_KEY_RIGHT},
                                           {ImGuiKey_UpArrow, GLFW_KEY_UP},
                                           {ImGuiKey_DownArrow, GLFW_KEY_DOWN},
                                           {ImGuiKey_PageUp, GLFW_KEY_PAGE_UP},
                                           {ImGuiKey_PageDown, GLFW_KEY_PAGE_DOWN},
                                           {ImGuiKey_Home, GLFW_KEY_HOME},
                                           {ImGuiKey_End, GLFW_KEY_END},
                                           {ImGuiKey_Insert, GLFW_KEY_INSERT},
                                           {ImGuiKey_Delete, GLFW_KEY_DELETE},
                                           {ImGuiKey_Backspace, GLFW_KEY_BACKSPACE},
                                           {ImGuiKey_Space, GLFW_KEY_SPACE},
                                           {ImGuiKey_Enter, GLFW_KEY_ENTER},
                                           {ImGuiKey_Escape, GLFW_KEY_ESCAPE},
                                           {ImGuiKey_KeyPadEnter, GLFW_KEY_KP_ENTER},
                                           {ImGuiKey_A, GLFW_KEY_A},
                                           {ImGuiKey_C, GLFW_KEY_C},
                                           {ImGuiKey_V, GLFW_KEY_V},
                                           {ImGuiKey_X, GLFW_KEY_X},
                                           {ImGuiKey_Y, GLFW_KEY_Y},
                                           {ImGuiKey_Z, GLFW_KEY_Z}};
  for (const auto& [imgui, glfwKey] : keys)
    io.KeyMap[imgui] = glfwKey;
}

DesktopInput::DesktopInput(GLFWwindow* window, Session& session) : window_(window), session_(session) {
  glfw::glfwSetWindowUserPointer(window, this);
  glfw::glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) { of(w).cursor(x, y); });
  glfw::glfwSetMouseButtonCallback(
      window, [](GLFWwindow* w, int button, int action, int mods) { of(w).button(button, action, mods); });
  glfw::glfwSetScrollCallback(window, [](GLFWwindow* w, double, double y) { of(w).scroll(y); });
  glfw::glfwSetKeyCallback(
      window, [](GLFWwindow* w, int key, int, int action, int mods) { of(w).key(key, action, mods); });
  glfw::glfwSetCharCallback(window, [](GLFWwindow* w, unsigned int c) {
    ImGui::GetIO().AddInputCharacter(c);
    of(w).arrived_ = true;
  });
  glfw::glfwSetWindowRefreshCallback(window, [](GLFWwindow* w) { of(w).arrived_ = true; });
}

DesktopInput& DesktopInput::of(GLFWwindow* window) {
  return *static_cast<DesktopInput*>(glfw::glfwGetWindowUserPointer(window));
}

// Window coordinates -> framebuffer pixels (they differ on high-DPI displays), where the session and the
// panel work.
glm::dvec2 DesktopInput::toPixels(double x, double y) const {
  int ww = 0, wh = 0, fw = 0, fh = 0;
  glfw::glfwGetWindowSize(window_, &ww, &wh);
  glfw::glfwGetFramebufferSize(window_, &fw, &fh);
  if (ww <= 0 || wh <= 0) return {x, y};
  return {x * fw / ww, y * fh / wh};
}

bool DesktopInput::panelWantsMouse() const {
  return panelVisible_ && ImGui::GetIO().WantCaptureMouse;
}

bool DesktopInput::overPanel() const {
  const std::array<float, 4>& r = panelRect_;
  return panelVisible_ && cursor_.x >= r[0] && cursor_.y >= r[1] && cursor_.x < r[0] + r[2] &&
         cursor_.y < r[1] + r[3];
}

void DesktopInput::panelFrameDone() {
  ImGuiIO& io = ImGui::GetIO();
  for (int b = 0; b < 3; ++b) {
    if (releasePending_[b]) io.MouseDown[b] = false;
    if (releasePending_[b]) arrived_ = true; // one more frame, for ImGui to see the release
    releasePending_[b] = false;
    pressedThisFrame_[b] = false;
  }
}

bool DesktopInput::panelWantsKeyboard() const {
  return panelVisible_ && ImGui::GetIO().WantCaptureKeyboard;
}

void DesktopInput::cursor(double x, double y) {
  arrived_ = true;
  cursor_ = toPixels(x, y);
  ImGui::GetIO().MousePos = ImVec2(float(cursor_.x), float(cursor_.y));
  if (dragging_ || !panelWantsMouse()) session_.mouseMove(cursor_);
}

void DesktopInput::button(int button, int action, int mods) {
  arrived_ = true;
  if (button >= 0 && button < 3) {
    bool pressed = action == GLFW_PRESS;
    if (pressed) pressedThisFrame_[button] = true;
    if (!pressed && pressedThisFrame_[button])
      releasePending_[button] = true;
    else
      ImGui::GetIO().MouseDown[button] = pressed;
  }
  MouseButton which = button == GLFW_MOUSE_BUTTON_LEFT    ? MouseButton::Left
                      : button == GLFW_MOUSE_BUTTON_RIGHT ? MouseButton::Right
                                                          : MouseButton::Middle;
  if (action == GLFW_RELEASE) {
    // A Ctrl+press released where it was is a click of the pick tool; released elsewhere, a drag that moves
    // the measurement's vertex under the press.
    if (which == MouseButton::Left && toolPress_) {
      const auto [at, measure] = *std::exchange(toolPress_, std::nullopt);
      if (glm::length(cursor_ - at) <= kDoubleClickPixels)
        session_.toolClick(at, measure);
      else
        session_.toolDrag(at, cursor_);
      return;
    }
    if (dragging_) session_.mouseUp(which, cursor_);
    dragging_ = false;
    return;
  }
  if (panelWantsMouse() || overPanel()) return;
  // Ctrl+click: the pick tool, not a drag; with Shift the picked point is the next vertex of a measurement.
  if (which == MouseButton::Left && (mods & GLFW_MOD_CONTROL)) {
    toolPress_ = {cursor_, (mods & GLFW_MOD_SHIFT) != 0};
    return;
  }
  double now = glfw::glfwGetTime();
  if (which == MouseButton::Left && now - lastClickTime_ < kDoubleClickSeconds &&
      glm::length(cursor_ - lastClick_) <= kDoubleClickPixels) {
    session_.doubleClick(cursor_);
    lastClickTime_ = -1;
    return;
  }
  if (which == MouseButton::Left) {
    lastClickTime_ = now;
    lastClick_ = cursor_;
  }
  session_.mouseDown(which, cursor_);
  dragging_ = true;
}

void DesktopInput::scroll(double y) {
  arrived_ = true;
  ImGui::GetIO().MouseWheel += float(y);
  if (!panelWantsMouse()) wheel_ += y;
}

std::optional<WheelInput> DesktopInput::takeWheel() {
  if (wheel_ == 0) return std::nullopt;
  return WheelInput{cursor_, std::exchange(wheel_, 0.0)};
}

void DesktopInput::key(int key, int action, int mods) {
  arrived_ = true;
  ImGuiIO& io = ImGui::GetIO();
  if (key >= 0 && key < int(IM_ARRAYSIZE(io.KeysDown))) io.KeysDown[key] = action != GLFW_RELEASE;
  io.KeyCtrl = mods & GLFW_MOD_CONTROL;
  io.KeyShift = mods & GLFW_MOD_SHIFT;
  io.KeyAlt = mods & GLFW_MOD_ALT;
  io.KeySuper = mods & GLFW_MOD_SUPER;
  // Ctrl+S saves the measurements (not the S of flying).
  if (key == GLFW_KEY_S && (mods & GLFW_MOD_CONTROL)) {
    if (action == GLFW_PRESS && !panelWantsKeyboard()) saveMeasurements_ = true;
    return;
  }
  std::optional<Key> k = sessionKey(key);
  if (!k) return;
  if (action == GLFW_RELEASE) {
    session_.keyUp(*k); // always: a fly key pressed before the panel took the keyboard must stop
    return;
  }
  if (panelWantsKeyboard()) return;
  bool fly = *k >= Key::Forward && *k <= Key::Up;
  // Held keys repeat; only flying cares (and ignores repeats, it tracks held state).
  if (action == GLFW_REPEAT && !fly) return;
  session_.keyDown(*k, mods & GLFW_MOD_SHIFT);
}

} // namespace pointrast::view
