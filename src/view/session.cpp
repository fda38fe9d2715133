#include "view/session.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "gpu/timer.h"

namespace pointrast::view {

std::optional<StandardView> standardViewForKey(Key key) {
  switch (key) {
  case Key::ViewTop:
    return StandardView::Top;
  case Key::ViewBottom:
    return StandardView::Bottom;
  case Key::ViewFront:
    return StandardView::Front;
  case Key::ViewBack:
    return StandardView::Back;
  case Key::ViewLeft:
    return StandardView::Left;
  case Key::ViewRight:
    return StandardView::Right;
  case Key::ViewIso:
    return StandardView::Iso;
  default:
    return std::nullopt;
  }
}

Session::Session(const Bounds& bounds, const Camera& camera, Viewport viewport, const ViewSettings& settings)
    : navigation_(bounds, camera), viewport_(viewport), settings_(settings) {}

void Session::mouseDown(MouseButton button, glm::dvec2 position) {
  cursor_ = position;
  navigation_.beginDrag(button == MouseButton::Left ? DragMode::Orbit : DragMode::Pan, position);
}

void Session::mouseMove(glm::dvec2 position) {
  cursor_ = position;
  if (navigation_.dragMode() != DragMode::None && navigation_.drag(position, viewport_)) ++generation_;
}

void Session::mouseUp(MouseButton, glm::dvec2 position) {
  mouseMove(position);
  navigation_.endDrag();
}

void Session::doubleClick(glm::dvec2 position) {
  navigation_.endDrag();
  requests_.pick = position;
}

void Session::wheel(glm::dvec2 position, double steps, std::optional<double> depth) {
  if (steps == 0) return;
  navigation_.zoom(position, steps, viewport_, depth);
  ++generation_;
}

void Session::flyKey(Key key, int value) {
  flyKeys_[int(key) - int(Key::Forward)] = value;
  fly_.forward = flyKeys_[0] - flyKeys_[1];
  fly_.right = flyKeys_[3] - flyKeys_[2];
  fly_.up = flyKeys_[5] - flyKeys_[4];
}

void Session::keyDown(Key key, bool shift) {
  if (key >= Key::Forward && key <= Key::Up) {
    fly_.fast = shift;
    flyKey(key, 1);
    return;
  }
  if (auto view = standardViewForKey(key)) {
    navigation_.viewFrom(*view, viewport_);
    ++generation_;
    return;
  }
  switch (key) {
  case Key::FrameAll:
    navigation_.frameAll(viewport_);
    ++generation_;
    break;
  case Key::Keyframe:
    recordKeyframe();
    break;
  case Key::TogglePanel:
    options_.panel = !options_.panel;
    break;
  case Key::PrintCamera:
    requests_.printCamera = true;
    break;
  case Key::Screenshot:
    requests_.screenshot = true;
    break;
  case Key::Quit:
    requests_.quit = true;
    break;
  default:
    break;
  }
}

void Session::keyUp(Key key) {
  if (key >= Key::Forward && key <= Key::Up) flyKey(key, 0);
}

void Session::resize(Viewport viewport) {
  if (viewport == viewport_ || viewport.width == 0 || viewport.height == 0) return;
  viewport_ = viewport;
  ++generation_;
}

bool Session::advance(double seconds) {
  // A long stall (a slow frame, a dragged window) must not throw the camera far away.
  if (!navigation_.fly(fly_, std::min(seconds, 0.1))) return false;
  ++generation_;
  return true;
}

void Session::pivotPicked(std::optional<glm::dvec3> point) {
  if (point) navigation_.setPivot(*point);
}

Requests Session::takeRequests() {
  return std::exchange(requests_, Requests{});
}

void Session::setCamera(const Camera& camera) {
  navigation_.setCamera(camera);
  ++generation_;
}

void Session::setSettings(const ViewSettings& settings) {
  if (settings == settings_) return;
  settings_ = settings;
  ++generation_;
}

bool Session::needsFrame() {
  if (content_ && content_->changedSinceLastFrame()) ++generation_;
  return generation_ != renderedGeneration_ || fly_.any();
}

void Session::frameRendered(const FrameReport& report) {
  renderedGeneration_ = generation_;
  recent_.push_back(report);
  if (recent_.size() > kStatsWindow) recent_.pop_front();
  auto medianOf = [&](double FrameReport::*member) {
    std::vector<double> values;
    for (const FrameReport& r : recent_)
      values.push_back(r.*member);
    return gpu::median(values);
  };
  statistics_.frames++;
  statistics_.renderMs = medianOf(&FrameReport::renderMs);
  statistics_.presentMs = medianOf(&FrameReport::presentMs);
  statistics_.hostMs = medianOf(&FrameReport::seconds) * 1e3;
  statistics_.points = report.points;
  statistics_.batch = report.batch;
  statistics_.gpuBytes = report.gpuBytes;
}

} // namespace pointrast::view
