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
  glfw::glfwSetCharCallback(window, [](GLFWwindow* w, unsigned int c) { of(w).character(c); });
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

// Whether the cursor is the panel's: ImGui's word about the last frame, unless the cursor moved since (a
// move and a wheel step or press in one batch of events), where the panel's windows' rectangles decide.
bool DesktopInput::forPanel() const {
  return movedSinceFrame_ ? overPanel() : panelWantsMouse();
}

bool DesktopInput::overPanel() const {
  if (!panelVisible_) return false;
  for (const std::array<float, 4>& r : panelRects_)
    if (cursor_.x >= r[0] && cursor_.y >= r[1] && cursor_.x < r[0] + r[2] && cursor_.y < r[1] + r[3])
      return true;
  return false;
}

void DesktopInput::panelFrameDone() {
  ImGuiIO& io = ImGui::GetIO();
  for (int b = 0; b < 3; ++b) {
    if (releasePending_[b]) io.MouseDown[b] = false;
    if (releasePending_[b]) arrived_ = true; // one more frame, for ImGui to see the release
    releasePending_[b] = false;
    pressedThisFrame_[b] = false;
  }
  for (size_t k = 0; k < keyReleasePending_.size(); ++k)
    if (keyReleasePending_[k]) io.KeysDown[k] = false;
  // ImGui reads the modifiers and the cursor while it builds the frame: those that came after a held press
  // or release change before the next frame.
  if (modsPending_) modsDue_ = std::exchange(modsPending_, std::nullopt);
  charsDue_.insert(charsDue_.end(), charsPending_.begin(), charsPending_.end());
  charsPending_.clear();
  if (cursorPending_) cursorDue_ = std::exchange(cursorPending_, std::nullopt);
  if (keyReleasePending_.any() || modsDue_ || cursorDue_) arrived_ = true;
  keyReleasePending_.reset();
  keyPressedThisFrame_.reset();
  movedSinceFrame_ = false;
  if (panelPressFrames_ > 0 && --panelPressFrames_ > 0) arrived_ = true;
  releaseHeld();
  if (!held_.empty()) arrived_ = true;
}

void DesktopInput::setPanelVisible(bool visible) {
  panelVisible_ = visible;
  if (!visible) { // no panel frame will come to release what is held
    panelPressFrames_ = 0;
    releaseHeld();
  }
}

// Input is held, in the order it came, from the first event that must wait for a frame: keys and characters
// after a press on the panel (until ImGui's capture flag knows whether the press focused a text field), a
// press after text ImGui has not yet seen (the click would end the field's editing before the text reached
// it). The events after a held one wait behind it.
bool DesktopInput::hold(const HeldInput& e) {
  if (!panelVisible_) return false;
  bool wait = !held_.empty();
  if (e.kind == HeldInput::Key || e.kind == HeldInput::Character) wait = wait || panelPressFrames_ > 0;
  if (e.kind == HeldInput::Button && e.action == GLFW_PRESS)
    wait = wait || !charsPending_.empty() || !charsDue_.empty() || keyReleasePending_.any() || modsPending_ ||
           modsDue_ || !ImGui::GetIO().InputQueueCharacters.empty();
  if (wait) {
    held_.push_back(e);
    arrived_ = true;
  }
  return wait;
}

void DesktopInput::releaseHeld() {
  std::vector<HeldInput> events = std::exchange(held_, {});
  for (size_t i = 0; i < events.size(); ++i) {
    if (!held_.empty()) { // one had to wait again: it and those after it stay in order
      held_.insert(held_.end(), events.begin() + std::ptrdiff_t(i), events.end());
      return;
    }
    const HeldInput& e = events[i];
    switch (e.kind) {
    case HeldInput::Cursor:
      cursor(e.x, e.y);
      break;
    case HeldInput::Button:
      button(e.key, e.action, e.mods);
      break;
    case HeldInput::Key:
      key(e.key, e.action, e.mods);
      break;
    case HeldInput::Character:
      character(e.codepoint);
      break;
    case HeldInput::Scroll:
      scroll(e.y);
      break;
    }
  }
}

// ImGui drops characters typed while Ctrl is down: those that follow a held Ctrl+key wait for its modifiers.
void DesktopInput::character(unsigned int c) {
  arrived_ = true;
  if (hold({HeldInput::Character, 0, 0, 0, c, 0, 0})) return;
  if (modsPending_)
    charsPending_.push_back(c);
  else if (modsDue_ || !charsDue_.empty())
    charsDue_.push_back(c);
  else
    ImGui::GetIO().AddInputCharacter(c);
}

void DesktopInput::panelFrameStart() {
  if (modsDue_) applyMods(*std::exchange(modsDue_, std::nullopt));
  for (unsigned int c : charsDue_)
    ImGui::GetIO().AddInputCharacter(c);
  charsDue_.clear();
  if (cursorDue_) ImGui::GetIO().MousePos = ImVec2(float(cursorDue_->x), float(cursorDue_->y));
  cursorDue_.reset();
}

void DesktopInput::applyMods(int mods) {
  ImGuiIO& io = ImGui::GetIO();
  io.KeyCtrl = mods & GLFW_MOD_CONTROL;
  io.KeyShift = mods & GLFW_MOD_SHIFT;
  io.KeyAlt = mods & GLFW_MOD_ALT;
  io.KeySuper = mods & GLFW_MOD_SUPER;
}

bool DesktopInput::panelWantsKeyboard() const {
  return panelVisible_ && ImGui::GetIO().WantCaptureKeyboard;
}

void DesktopInput::cursor(double x, double y) {
  arrived_ = true;
  if (hold({HeldInput::Cursor, 0, 0, 0, 0, x, y})) return;
  cursor_ = toPixels(x, y);
  movedSinceFrame_ = true;
  // A button pressed since the last frame is seen by ImGui where it was pressed (a click, then a move
  // away before the frame is built, is still a click on the control under the press).
  const bool held = pressedThisFrame_[0] || pressedThisFrame_[1] || pressedThisFrame_[2];
  if (held && panelVisible_) {
    cursorPending_ = cursor_;
  } else {
    cursorDue_.reset();
    ImGui::GetIO().MousePos = ImVec2(float(cursor_.x), float(cursor_.y));
  }
  if (dragging_ || !panelWantsMouse()) session_.mouseMove(cursor_);
}

void DesktopInput::button(int button, int action, int mods) {
  arrived_ = true;
  if (hold({HeldInput::Button, button, action, mods, 0, 0, 0})) return;
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
  if (forPanel() || overPanel()) {
    panelPressFrames_ = 2; // the frame that sees the press, then the one whose capture flag knows of it
    return;
  }
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
  if (hold({HeldInput::Scroll, 0, 0, 0, 0, 0, y})) return;
  if (forPanel())
    ImGui::GetIO().MouseWheel += float(y);
  else
    wheel_ += y;
}

std::optional<WheelInput> DesktopInput::takeWheel() {
  if (wheel_ == 0) return std::nullopt;
  return WheelInput{cursor_, std::exchange(wheel_, 0.0)};
}

void DesktopInput::key(int key, int action, int mods) {
  arrived_ = true;
  if (hold({HeldInput::Key, key, action, mods, 0, 0, 0})) return;
  // X11 reports the modifiers as they were before the event: a modifier's own release still holds it.
  if (action == GLFW_RELEASE) {
    if (key == GLFW_KEY_LEFT_CONTROL || key == GLFW_KEY_RIGHT_CONTROL) mods &= ~GLFW_MOD_CONTROL;
    if (key == GLFW_KEY_LEFT_SHIFT || key == GLFW_KEY_RIGHT_SHIFT) mods &= ~GLFW_MOD_SHIFT;
    if (key == GLFW_KEY_LEFT_ALT || key == GLFW_KEY_RIGHT_ALT) mods &= ~GLFW_MOD_ALT;
    if (key == GLFW_KEY_LEFT_SUPER || key == GLFW_KEY_RIGHT_SUPER) mods &= ~GLFW_MOD_SUPER;
  }
  // As with the mouse buttons: a key released in the frame of its press (a quick tap, Ctrl+A typed by a
  // script) stays down, with its modifiers, until ImGui has seen it once.
  ImGuiIO& io = ImGui::GetIO();
  if (key >= 0 && size_t(key) < keyPressedThisFrame_.size()) {
    if (action == GLFW_PRESS) keyPressedThisFrame_[size_t(key)] = true;
    if (action == GLFW_RELEASE && keyPressedThisFrame_[size_t(key)] && panelVisible_)
      keyReleasePending_[size_t(key)] = true;
    else
      io.KeysDown[key] = action != GLFW_RELEASE;
  }
  if (keyReleasePending_.any() && panelVisible_) {
    modsPending_ = mods;
  } else {
    modsDue_.reset();
    applyMods(mods);
  }
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
