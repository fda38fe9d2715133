#include "view/desktop/viewer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <system_error>

#include <imgui.h>
#include <nlohmann/json.hpp>

#include "base/error.h"
#include "cloud/cloud.h"
#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu/swapchain.h"
#include "io/annotations_file.h"
#include "io/format_table.h"
#include "io/writer.h"
#include "view/desktop/glfw_api.h"
#include "view/desktop/input.h"
#include "view/desktop/panel.h"
#include "view/desktop/presenter.h"
#include "view/flight.h"
#include "view/profile_tool.h"
#include "view/scene_view.h"

namespace pointrast::view {

namespace {

// While idle the loop sleeps in the window system until an event comes, waking this often at most.
constexpr double kIdleWaitSeconds = 0.5;

// GLFW's library and its window, released in the right order by scope.
struct GlfwLibrary {
  GlfwLibrary() {
    glfw::load();
    glfw::glfwSetErrorCallback(
        [](int, const char* text) { std::fprintf(stderr, "pointrast: GLFW: %s\n", text); });
    if (!glfw::glfwInit())
      throw UnsupportedError("cannot open the display: use `pointrast serve` to view in a browser, or "
                             "`pointrast render` for images");
  }
  ~GlfwLibrary() { glfw::glfwTerminate(); }
};

struct Window {
  GLFWwindow* handle = nullptr;
  Window(uint32_t width, uint32_t height, const std::string& title) {
    glfw::glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API); // Vulkan draws, no OpenGL context
    handle = glfw::glfwCreateWindow(int(width), int(height), title.c_str(), nullptr, nullptr);
    if (!handle) throw UnsupportedError("cannot create a window on this display");
  }
  ~Window() { glfw::glfwDestroyWindow(handle); }
};

struct ImGuiContextScope {
  ImGuiContextScope() {
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr; // the panel's layout is not worth a file in the user's folder
    io.LogFilename = nullptr;
    mapImGuiKeys(io);
  }
  ~ImGuiContextScope() { ImGui::DestroyContext(); }
};

gpu::Context createContext(const ViewerOptions& options) {
  if (!glfw::glfwVulkanSupported())
    throw UnsupportedError("GLFW finds no Vulkan loader to show a window with");
  uint32_t count = 0;
  const char** names = glfw::glfwGetRequiredInstanceExtensions(&count);
  if (!names) throw UnsupportedError("this display offers no Vulkan surface extension");
  gpu::ContextOptions contextOptions;
  contextOptions.deviceIndex = options.device;
  contextOptions.surfaceExtensions.assign(names, names + count);
  return gpu::Context(contextOptions);
}

nlohmann::json vec(const glm::dvec3& v) {
  return {v.x, v.y, v.z};
}

nlohmann::json cameraJson(const Camera& c) {
  return {{"eye", vec(c.eye)}, {"target", vec(c.target)}, {"up", vec(c.up)}, {"fov", c.fovY}};
}

void emit(const nlohmann::json& event) {
  std::printf("%s\n", event.dump().c_str());
  std::fflush(stdout);
}

// pointrast-0001.png, pointrast-0002.png, ... (`pattern`): the first name not taken in the folder.
std::filesystem::path numberedName(const std::filesystem::path& folder, const char* pattern) {
  for (uint32_t n = 1;; ++n) {
    char name[64];
    std::snprintf(name, sizeof name, pattern, n);
    std::filesystem::path p = folder / name;
    std::error_code error;
    if (!std::filesystem::exists(p, error)) return p;
  }
}

class Viewer {
public:
  Viewer(SceneInput& input, const ViewerOptions& options, gpu::Context& context, GLFWwindow* window,
         gpu::Swapchain& swapchain);
  int run();

private:
  void showFrame();
  void drawMeasurements();
  void handleRequests();
  void handlePanel(const PanelActions& actions);
  void takeScreenshot();
  void saveKeyframes();
  void saveMeasurements();
  void exportClipped();
  void cutProfile(const PanelActions& actions);
  ImDrawData* buildPanelFrame(double seconds);

  const ViewerOptions& options_;
  gpu::Context& context_;
  GLFWwindow* window_;
  gpu::Swapchain& swapchain_;
  std::unique_ptr<SceneSource> source_;
  SceneView scene_;
  Session session_;
  DesktopInput input_;
  Presenter presenter_;
  PanelInfo info_;
  PanelItems items_;
  ShownImage shown_;
  // The shown frame with the measurements drawn over it (host-visible; the presenter reads it by address).
  gpu::Buffer overlay_;
  int presentsPending_ = 1;
  size_t savedKeyframes_ = 0;
  bool swapchainStale_ = false;
  bool running_ = true;
};

Camera startCamera(const SceneInput& input, const ViewerOptions& options, Viewport viewport) {
  if (options.camera) return *options.camera;
  return overviewCamera(input.bounds, viewport.aspect(), options.fovY, input.framing);
}

// The settings the session starts with: the options', with the method the source and device call for
// unless one was named. Throws InputError for a named method that does not draw this input.
ViewSettings startSettings(const SceneSource& source, const ViewerOptions& options,
                           const gpu::Context& context) {
  ViewSettings settings = options.settings;
  settings.method = options.method ? *options.method : defaultMethod(source, context);
  if (!source.draws(settings.method)) throw InputError(notDrawn(source, settings.method));
  return settings;
}

Viewport framebufferViewport(GLFWwindow* window) {
  int w = 0, h = 0;
  glfw::glfwGetFramebufferSize(window, &w, &h);
  return {uint32_t(std::max(w, 1)), uint32_t(std::max(h, 1))};
}

Viewer::Viewer(SceneInput& input, const ViewerOptions& options, gpu::Context& context, GLFWwindow* window,
               gpu::Swapchain& swapchain)
    : options_(options), context_(context), window_(window), swapchain_(swapchain),
      source_(options.makeSource ? options.makeSource(context, input, options.settings)
                                 : makeSceneSource(context, input, options.settings, true)),
      scene_(context, *source_),
      session_(input.bounds, startCamera(input, options, {swapchain.width(), swapchain.height()}),
               {swapchain.width(), swapchain.height()}, startSettings(*source_, options, context)),
      input_(window, session_), presenter_(context, swapchain) {
  session_.options().panel = options.panel;
  session_.setContentSource(&scene_);
  std::error_code error;
  if (std::filesystem::exists(options.pathFile, error)) {
    CameraPath loaded = CameraPath::load(options.pathFile);
    session_.path() = loaded;
    savedKeyframes_ = loaded.keyframes().size();
  }
  info_.device = context.info().name;
  info_.input = input.name;
  info_.points = input.points;
  info_.pathFile = options.pathFile.string();
  info_.annotationsFile = options.annotationsFile.string();
  if (!options.annotationsFile.empty() && std::filesystem::exists(options.annotationsFile, error))
    session_.measurements().load(io::loadAnnotations(options.annotationsFile));
  info_.methods = methodsFor(*source_, context);
  // A strip a hundredth of the cloud's larger horizontal extent wide.
  const glm::dvec3 extent = input.bounds.max - input.bounds.min;
  info_.profileWidth = std::max(extent.x, extent.y) > 0 ? std::max(extent.x, extent.y) / 100 : 1;
}

ImDrawData* Viewer::buildPanelFrame(double seconds) {
  input_.setPanelVisible(session_.options().panel);
  if (!session_.options().panel) return nullptr;
  ImGuiIO& io = ImGui::GetIO();
  io.DisplaySize = ImVec2(float(swapchain_.width()), float(swapchain_.height()));
  io.DeltaTime = float(std::max(seconds, 1e-4));
  input_.panelFrameStart();
  ImGui::NewFrame();
  input_.panelFrameDone();
  ViewSettings edited = session_.settings();
  PanelActions actions = buildPanel(session_, info_, edited, items_);
  ImGui::Render();
  std::vector<std::array<float, 4>> rects = {items_["panel"]};
  if (items_.count("profile window")) rects.push_back(items_["profile window"]);
  input_.setPanelRects(std::move(rects));
  session_.setSettings(edited);
  handlePanel(actions);
  return ImGui::GetDrawData();
}

void Viewer::handlePanel(const PanelActions& actions) {
  Viewport viewport = session_.viewport();
  if (actions.frameAll) session_.keyDown(Key::FrameAll);
  if (actions.view) {
    session_.navigation().viewFrom(*actions.view, viewport);
    session_.invalidate();
  }
  if (actions.addKeyframe) session_.keyDown(Key::Keyframe);
  if (actions.clearKeyframes) {
    session_.path().clear();
    saveKeyframes();
  }
  if (actions.screenshot) takeScreenshot();
  if (actions.deleteMeasurement && session_.measurements().remove(*actions.deleteMeasurement))
    session_.invalidate();
  if (actions.saveMeasurements) saveMeasurements();
  if (actions.exportLas) exportClipped();
  if (actions.profile || actions.profileLas || actions.profileCsv || actions.profilePng) cutProfile(actions);
}

// The profile of the panel's line and width through `pointrast profile`'s code (view/profile_tool.h), read
// from the input file: Cut shows its picture; an export writes the panel's file (temporary name, renamed).
void Viewer::cutProfile(const PanelActions& actions) {
  constexpr uint32_t kProfileWidth = 720, kProfileHeight = 300;
  nlohmann::json event = {{"event", "profile"}};
  try {
    ProfileRequest request;
    request.input = options_.inputFile.string();
    std::error_code error;
    if (request.input.empty() || !std::filesystem::exists(options_.inputFile, error))
      throw InputError("a profile is cut from a file or octree, not " + info_.input);
    request.line.vertices = parseProfileVertices(info_.profileLineText.data(), "the profile's line", 1000);
    request.line.width = info_.profileWidth;
    if (!(request.line.width > 0) || !std::isfinite(request.line.width))
      throw InputError("the profile's width must be a positive length");
    if (!(profileLength(request.line) > 0)) throw InputError("the profile's line has no length");
    request.filter = session_.settings().filter;
    std::filesystem::path file;
    const bool exporting = actions.profileLas || actions.profileCsv || actions.profilePng;
    if (exporting) {
      file = info_.profileFileText.data();
      if (file.empty()) file = options_.screenshotDir / "pointrast-profile";
      if (!file.has_filename()) throw InputError("type the file to export the profile to");
      file.replace_extension(actions.profileLas ? ".las" : actions.profileCsv ? ".csv" : ".png");
    }
    if (actions.profile || actions.profilePng) {
      request.imageWidth = kProfileWidth;
      request.imageHeight = kProfileHeight;
    }
    if (actions.profileLas) request.las = file.string();
    if (actions.profileCsv) request.csv = file.string();
    const ProfileResult result = view::cutProfile(request);
    if (!result.pixels.empty()) {
      presenter_.setPanelImage(request.imageWidth, request.imageHeight, result.pixels.data());
      info_.profileImageWidth = request.imageWidth;
      info_.profileImageHeight = request.imageHeight;
    }
    if (actions.profilePng) io::writePng(file, request.imageWidth, request.imageHeight, result.pixels.data());
    info_.profileStatus =
        std::to_string(result.points) + " points" + (file.empty() ? "" : " in " + file.string());
    event["points"] = result.points;
    event["line"] = info_.profileLineText.data();
    event["strip_width"] = request.line.width;
    event["width"] = request.imageWidth;
    event["height"] = request.imageHeight;
    if (!file.empty()) event["file"] = file.string();
  } catch (const InputError& e) {
    info_.profileStatus = e.what();
    event["error"] = e.what();
    if (!options_.events) std::fprintf(stderr, "%s\n", e.what());
  }
  if (options_.events)
    emit(event);
  else if (!event.contains("error"))
    std::printf("profile: %s\n", info_.profileStatus.c_str());
  std::fflush(stdout);
}

// The input's points that the applied clip box keeps, as LAS beside the screenshots, through convert's
// filter path (records byte for byte, as `convert --clip-box` writes them).
void Viewer::exportClipped() {
  const std::filesystem::path file = numberedName(options_.screenshotDir, "pointrast-export-%04u.las");
  nlohmann::json event = {{"event", "exported"}};
  try {
    const std::filesystem::path& input = options_.inputFile;
    std::error_code error;
    const io::FormatInfo* format =
        std::filesystem::is_regular_file(input, error) ? io::detectFormat(input) : nullptr;
    const std::string name = format ? format->name : "";
    if (name != "LAS" && name != "LAZ" && name != "COPC")
      throw InputError("export writes the points of a LAS, LAZ or COPC file, not " + info_.input);
    io::LasConvertOptions convert;
    convert.filter = &session_.settings().filter;
    const uint64_t points = io::convertLasFile(input, file, convert);
    info_.exported = file.string() + ": " + std::to_string(points) + " points";
    event["file"] = file.string();
    event["points"] = points;
  } catch (const InputError& e) {
    info_.exported = e.what();
    event["error"] = e.what();
    if (!options_.events) std::fprintf(stderr, "%s\n", e.what());
  }
  if (options_.events)
    emit(event);
  else if (!event.contains("error"))
    std::printf("export: %s\n", info_.exported.c_str());
  std::fflush(stdout);
}

// The measurements that can be measured, to --annotations (written under a temporary name, then renamed).
void Viewer::saveMeasurements() {
  if (options_.annotationsFile.empty()) {
    std::fprintf(stderr, "measurements: start the viewer with --annotations FILE to save them\n");
    return;
  }
  const Annotations annotations = session_.measurements().complete();
  io::saveAnnotations(options_.annotationsFile, annotations);
  if (options_.events)
    emit({{"event", "annotations"},
          {"count", annotations.items.size()},
          {"file", options_.annotationsFile.string()}});
  else
    std::printf("measurements: %s (%zu)\n", options_.annotationsFile.string().c_str(),
                annotations.items.size());
  std::fflush(stdout);
}

// Lines of a pick's attributes for the panel.
std::string pickedText(const nlohmann::json& pick) {
  const nlohmann::json& p = pick["point"];
  if (!p.is_object()) return p.is_string() ? p.get<std::string>() : std::string();
  std::string text;
  for (const auto& [name, value] : p.items())
    if (name == "extra_bytes" && value.is_object()) {
      // An octree's extra bytes fields, each under its own name.
      for (const auto& [field, v] : value.items())
        text += field + " " + v.dump() + "\n";
    } else if (name != "index") {
      text += name + " " + value.dump() + "\n";
    }
  return text;
}

void Viewer::saveKeyframes() {
  session_.path().save(options_.pathFile);
  savedKeyframes_ = session_.path().keyframes().size();
  if (options_.events)
    emit({{"event", "keyframes"},
          {"count", session_.path().keyframes().size()},
          {"duration", session_.path().duration()},
          {"file", options_.pathFile.string()}});
  else
    std::printf("%zu keyframes (%.2f s) saved to %s\n", session_.path().keyframes().size(),
                session_.path().duration(), options_.pathFile.string().c_str());
}

void Viewer::takeScreenshot() {
  std::filesystem::path file = numberedName(options_.screenshotDir, "pointrast-%04u.png");
  Viewport viewport = session_.viewport();
  std::vector<uint32_t> pixels =
      scene_.screenshot(session_.camera(), session_.settings(), viewport, session_.options().supersample);
  const Annotations annotations = session_.measurements().complete();
  if (!annotations.items.empty())
    scene_.drawOverlay(session_.camera(), session_.settings(), viewport, annotations, pixels);
  io::writePng(file, viewport.width, viewport.height, pixels.data());
  session_.invalidate(); // a supersampled shot used another renderer; draw the window's image again
  if (options_.events)
    emit({{"event", "screenshot"},
          {"file", file.string()},
          {"width", viewport.width},
          {"height", viewport.height}});
  else
    std::printf("screenshot: %s (%ux%u)\n", file.string().c_str(), viewport.width, viewport.height);
  std::fflush(stdout);
}

void Viewer::handleRequests() {
  if (Flight* flight = options_.flight)
    for (const FlightInput& in : flight->take(glfw::glfwGetTime()))
      applyFlightInput(session_, scene_, in);
  if (auto wheel = input_.takeWheel()) zoomAtCursor(session_, scene_, wheel->position, wheel->steps);
  Requests r = session_.takeRequests();
  if (r.pick) {
    std::optional<glm::dvec3> point = pickPivot(session_, scene_, *r.pick);
    if (options_.events)
      emit({{"event", "pick"},
            {"x", r.pick->x},
            {"y", r.pick->y},
            {"hit", point.has_value()},
            {"pivot", vec(session_.pivot())}});
  }
  if (r.toolPick) {
    std::optional<AnnotationKind> measure;
    if (r.toolMeasure) measure = session_.measurements().measureKind;
    nlohmann::json picked = pickTool(session_, scene_, *r.toolPick, measure);
    info_.picked = pickedText(picked);
    if (options_.events)
      emit({{"event", "picked"},
            {"x", r.toolPick->x},
            {"y", r.toolPick->y},
            {"pick", picked},
            {"measurements", nlohmann::json::parse(session_.measurements().json())}});
  }
  if (r.vertexMove) {
    nlohmann::json moved = moveVertexTool(session_, scene_, r.vertexMove->first, r.vertexMove->second);
    if (moved.contains("pick")) info_.picked = pickedText(moved["pick"]);
    if (options_.events)
      emit({{"event", "moved"},
            {"from", {r.vertexMove->first.x, r.vertexMove->first.y}},
            {"to", {r.vertexMove->second.x, r.vertexMove->second.y}},
            {"moved", moved},
            {"measurements", nlohmann::json::parse(session_.measurements().json())}});
  }
  if (input_.takeSaveMeasurements()) saveMeasurements();
  if (r.printCamera) {
    if (options_.events)
      emit({{"event", "camera"},
            {"camera", cameraJson(session_.camera())},
            {"pivot", vec(session_.pivot())},
            {"options", describeSettings(session_.settings())}});
    else
      std::printf("camera: %s\n", describeView(session_.camera(), session_.settings()).c_str());
    std::fflush(stdout);
  }
  if (r.screenshot) takeScreenshot();
  if (r.quit) running_ = false;
  // K records in the session as the key arrives; the file follows here.
  if (session_.path().keyframes().size() != savedKeyframes_) saveKeyframes();
}

void Viewer::showFrame() {
  bool rendered = false;
  FrameReport report;
  const auto start = std::chrono::steady_clock::now();
  if (session_.needsFrame()) {
    report = scene_.render(session_.camera(), session_.settings(), session_.viewport());
    shown_ = {scene_.renderer().imageAddress(), scene_.renderer().width(), scene_.renderer().height()};
    drawMeasurements();
    rendered = true;
  }
  if (!rendered && presentsPending_ == 0) return;
  Presenter::Result result =
      presenter_.present(shown_, session_.options().panel ? ImGui::GetDrawData() : nullptr);
  if (!result.presented) swapchainStale_ = true;
  presentsPending_ = std::max(0, presentsPending_ - 1);
  if (!rendered) return;
  report.presentMs = result.gpuMs;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  session_.frameRendered(report);
  if (Flight* flight = options_.flight) {
    // A cloud drawn whole is complete in every frame; an octree's frame says whether it converged.
    if (report.lod)
      flight->frameShown(glfw::glfwGetTime(), *report.lod);
    else
      flight->frameShown(glfw::glfwGetTime(), true);
    if (flight->done()) running_ = false;
  }
  if (options_.frameLog)
    options_.frameLog->add({report.renderMs, report.presentMs, report.seconds * 1e3},
                           methodName(session_.settings().method), {shown_.width, shown_.height});
  if (!options_.events) return;
  nlohmann::json event = {{"event", "frame"},
                          {"frame", session_.statistics().frames},
                          {"width", shown_.width},
                          {"height", shown_.height},
                          {"camera", cameraJson(session_.camera())},
                          {"pivot", vec(session_.pivot())},
                          {"method", methodName(session_.settings().method)},
                          {"background", session_.settings().background},
                          {"options", describeSettings(session_.settings())},
                          {"panel", session_.options().panel},
                          {"render_ms", report.renderMs},
                          {"present_ms", report.presentMs}};
  if (report.lod)
    event["lod"] = {{"converged", report.lod->converged},
                    {"nodes_drawn", report.lod->nodesDrawn},
                    {"points_drawn", report.lod->pointsDrawn},
                    {"nodes_loaded", report.lod->nodesLoaded},
                    {"nodes_evicted", report.lod->nodesEvicted}};
  if (!report.status.empty()) event["status"] = report.status;
  if (session_.options().panel) {
    nlohmann::json items = nlohmann::json::object();
    for (const auto& [label, rect] : items_)
      items[label] = {rect[0], rect[1], rect[2], rect[3]};
    event["panel_items"] = items;
  }
  emit(event);
}

// The measurements over the frame just rendered, as render --annotations draws them (render/overlay.h):
// the image comes to the host, is drawn over there and shown from a buffer of its own.
void Viewer::drawMeasurements() {
  const Annotations annotations = session_.measurements().complete();
  const Viewport viewport = session_.viewport();
  if (annotations.items.empty() || applicable(session_.settings()).stereo) return;
  if (shown_.width != viewport.width || shown_.height != viewport.height) return;
  std::vector<uint32_t> rgba = scene_.renderer().image();
  scene_.drawOverlay(session_.camera(), session_.settings(), viewport, annotations, rgba);
  const uint64_t bytes = rgba.size() * sizeof(uint32_t);
  if (!overlay_ || overlay_.size() != bytes)
    overlay_ = gpu::Buffer(context_, bytes, gpu::kBufferUsage, gpu::MemoryKind::Upload, "view overlay image");
  std::memcpy(overlay_.mapped(), rgba.data(), bytes);
  shown_.address = overlay_.address();
}

int Viewer::run() {
  const double opened = glfw::glfwGetTime();
  double last = opened;
  while (running_ && !glfw::glfwWindowShouldClose(window_)) {
    bool busy = session_.animating() || presentsPending_ > 0 || session_.needsFrame() || swapchainStale_;
    // A flight's next input falls due on the clock, not with an event.
    const double idle = options_.flight
                            ? std::min(kIdleWaitSeconds, options_.flight->wait(glfw::glfwGetTime()))
                            : kIdleWaitSeconds;
    if (busy || idle <= 0)
      glfw::glfwPollEvents();
    else
      glfw::glfwWaitEventsTimeout(idle);
    // Input changes the panel's look (hover, clicks): show two frames, the second with the settled state.
    if (input_.takeArrived()) presentsPending_ = std::max(presentsPending_, 2);
    double now = glfw::glfwGetTime();
    session_.advance(now - last);
    Viewport fb = framebufferViewport(window_);
    int w = 0, h = 0;
    glfw::glfwGetFramebufferSize(window_, &w, &h);
    if (w == 0 || h == 0) { // minimized: nothing to show
      last = now;
      continue;
    }
    if (swapchainStale_ || fb.width != swapchain_.width() || fb.height != swapchain_.height()) {
      swapchain_.recreate(fb.width, fb.height);
      session_.resize({swapchain_.width(), swapchain_.height()});
      swapchainStale_ = false;
      presentsPending_ = std::max(presentsPending_, 1);
    }
    handleRequests();
    buildPanelFrame(now - last);
    last = now;
    showFrame();
  }
  if (FrameLog* log = options_.frameLog) {
    log->device = context_.info();
    log->deviceLocalBytes = context_.deviceLocalBytes();
    log->seconds = glfw::glfwGetTime() - opened;
  }
  uint32_t errors = context_.validationErrors();
  if (options_.events && options_.flight) emit({{"event", "flight"}, {"flight", options_.flight->result()}});
  if (options_.events)
    emit({{"event", "exit"},
          {"frames", session_.statistics().frames},
          {"camera", cameraJson(session_.camera())},
          {"pivot", vec(session_.pivot())},
          {"validation_errors", errors}});
  if (errors > 0) {
    std::fprintf(stderr, "pointrast: the Vulkan validation layer reported %u error(s)\n", errors);
    return 1;
  }
  return 0;
}

} // namespace

bool hasDisplay() {
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  return (x11 && *x11) || (wayland && *wayland);
}

int runViewer(SceneInput& input, const ViewerOptions& options) {
  if (options.width == 0 || options.height == 0) throw InputError("--width and --height must be at least 1");
  if (input.points == 0) throw InputError(input.name + ": no points to view");
  GlfwLibrary library;
  gpu::Context context = createContext(options);
  Window window(options.width, options.height, options.title);
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  VK_CHECK(glfw::glfwCreateWindowSurface(context.instance(), window.handle, nullptr, &surface));
  Viewport fb = framebufferViewport(window.handle);
  gpu::Swapchain swapchain(context, surface, fb.width, fb.height, options.vsync);
  ImGuiContextScope imgui;
  Viewer viewer(input, options, context, window.handle, swapchain);
  return viewer.run();
}

} // namespace pointrast::view
