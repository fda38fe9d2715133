// pointrast._core: the compiled half of the Python module (python/pointrast/__init__.py holds the API and
// its docstrings). It does what `pointrast render` does for one frame: a cloud (cloud/cloud.h) or an octree
// (a NodeSource) drawn by a Renderer on one gpu::Context, with the CLI's camera contract and option checks.
// The GIL is released while the GPU works; errors of the library become Python exceptions carrying the
// same sentence as the CLI's one line (InputError: ValueError, a device that cannot: RuntimeError).
#include <algorithm>
#include <bitset>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arrays.h"
#include "base/error.h"
#include "cloud/attribute_colors.h"
#include "cloud/octree.h"
#include "cloud/point_filter.h"
#include "gpu/context.h"
#include "io/format_table.h"
#include "io/reader.h"
#include "io/writer.h"
#include "render/camera.h"
#include "render/clip_volumes.h"
#include "render/clock_settle.h"
#include "render/lod/lod_scene.h"
#include "render/renderer.h"
#include "render/scene.h"

namespace pointrast::python {

namespace {

// A cloud made in Python or read from a file. One made from arrays keeps them (ArrayPoints) and makes its
// PointCloud only when something needs it: an upload of the batched layout with RGB colors reads the
// arrays block by block, with no copy of the input on the host.
struct Cloud {
  explicit Cloud(std::shared_ptr<PointCloud> made) : made_(std::move(made)) {}
  explicit Cloud(std::shared_ptr<ArrayPoints> arrays) : arrays_(std::move(arrays)) {}
  // The PointCloud, made from the arrays the first time it is asked for. Called with the GIL held.
  const std::shared_ptr<PointCloud>& get() const {
    if (!made_) made_ = arrays_->makeCloud();
    return made_;
  }
  // The arrays while no PointCloud was made from them (a change to the cloud makes it), else null.
  const ArrayPoints* arrays() const { return made_ ? nullptr : arrays_.get(); }
  const std::shared_ptr<ArrayPoints>& arrayPoints() const { return arrays_; }
  const Bounds& bounds() const { return made_ ? made_->bounds : arrays_->shape().bounds; }
  uint64_t size() const { return made_ ? made_->size() : arrays_->size(); }
  const PointCloud& shape() const { return made_ ? *made_ : arrays_->shape(); }

private:
  mutable std::shared_ptr<PointCloud> made_;
  std::shared_ptr<ArrayPoints> arrays_;
};

struct Octree {
  std::shared_ptr<lod::NodeSource> source;
};

glm::dvec3 vec3(const py::handle& value, const char* what) {
  try {
    const auto v = value.cast<std::vector<double>>();
    if (v.size() == 3) return {v[0], v[1], v[2]};
  } catch (const py::cast_error&) {
  }
  throw py::value_error(std::string("camera ") + what + " must be three numbers (x, y, z)");
}

// The render options of the CLI, by their Python names (python/pointrast/__init__.py fills every key).
struct Options {
  uint32_t width = 1920, height = 1080;
  std::string method = "auto", depth = "float", precision = "adaptive";
  uint32_t background = 0xFF000000u;
  std::string color = "auto";
  std::optional<ColorRange> colorRange;
  PostSettings post;
  double minNodePx = 100;
  uint64_t pointBudget = 0, gpuMemory = 0;
  lod::Foveation foveation;
  bool lodOptionsGiven = false;
  uint32_t frames = 1; // timed frames: gpu_ms is their median
  PointFilter filter;  // clip volumes and attribute filters, as the CLI's Filters options
};

// A number pair (lo, hi) with lo <= hi, for the range filters.
std::pair<double, double> rangeOf(const py::handle& value, const char* name) {
  const auto r = value.cast<std::vector<double>>();
  if (r.size() != 2 || !std::isfinite(r[0]) || !std::isfinite(r[1]) || r[0] > r[1])
    throw InputError(std::string(name) + " must be (lo, hi) with lo <= hi");
  return {r[0], r[1]};
}

// clip_box, clip_polygon, clip_z, clip_mode, classes, returns, intensity_range, gps_time, source_ids: the
// CLI's --clip-box ... --source-ids, as Python values.
PointFilter parseFilter(const py::dict& d) {
  auto given = [&](const char* key) { return d.contains(key) && !d[key].is_none(); };
  PointFilter f;
  if (given("clip_box")) {
    py::object boxes = d["clip_box"];
    const bool one = py::len(boxes) > 0 && !py::isinstance<py::sequence>(boxes[py::int_(0)]);
    for (const py::handle box : one ? py::list(py::make_tuple(boxes)) : py::list(boxes)) {
      const auto v = box.cast<std::vector<double>>();
      if (v.size() != 6 || !std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); }) ||
          v[0] > v[3] || v[1] > v[4] || v[2] > v[5])
        throw InputError("clip_box must be (xmin, ymin, zmin, xmax, ymax, zmax) with each min <= max, or a "
                         "list of such boxes");
      f.boxes.push_back({{v[0], v[1], v[2]}, {v[3], v[4], v[5]}});
    }
  }
  if (given("clip_polygon")) {
    py::object polygons = d["clip_polygon"];
    // One polygon [(x, y), ...] or a list of them.
    const bool one = py::len(polygons) > 0 && py::len(polygons[py::int_(0)]) == 2 &&
                     !py::isinstance<py::sequence>(polygons[py::int_(0)][py::int_(0)]);
    for (const py::handle polygon : one ? py::list(py::make_tuple(polygons)) : py::list(polygons)) {
      ClipPolygon p;
      for (const py::handle vertex : polygon) {
        const auto v = vertex.cast<std::vector<double>>();
        if (v.size() != 2 || !std::isfinite(v[0]) || !std::isfinite(v[1]))
          throw InputError("clip_polygon vertices must be (x, y) pairs of finite numbers");
        p.vertices.push_back({v[0], v[1]});
      }
      if (p.vertices.size() < 3) throw InputError("clip_polygon needs at least three vertices");
      f.polygons.push_back(std::move(p));
    }
  }
  if (given("clip_z")) {
    if (f.polygons.empty()) throw InputError("clip_z applies to clip_polygon");
    const auto [lo, hi] = rangeOf(d["clip_z"], "clip_z");
    for (ClipPolygon& p : f.polygons) {
      p.zMin = lo;
      p.zMax = hi;
    }
  }
  const std::string mode = given("clip_mode") ? d["clip_mode"].cast<std::string>() : "inside";
  if (mode == "inside")
    f.clipMode = ClipMode::Inside;
  else if (mode == "outside")
    f.clipMode = ClipMode::Outside;
  else if (mode == "highlight")
    f.clipMode = ClipMode::Highlight;
  else
    throw InputError("clip_mode must be 'inside', 'outside' or 'highlight', not '" + mode + "'");
  if (given("clip_mode") && !f.hasClip()) throw InputError("clip_mode needs clip_box or clip_polygon");
  if (given("classes")) {
    std::bitset<256> keep;
    for (const py::handle c : d["classes"]) {
      const int64_t v = c.cast<int64_t>();
      if (v < 0 || v > 255) throw InputError("classes are classification values 0 to 255");
      keep.set(size_t(v));
    }
    f.classes = keep;
  }
  if (given("returns")) {
    const std::string r = d["returns"].cast<std::string>();
    if (r == "all")
      f.returns = ReturnFilter::All;
    else if (r == "first")
      f.returns = ReturnFilter::First;
    else if (r == "last")
      f.returns = ReturnFilter::Last;
    else if (r == "only")
      f.returns = ReturnFilter::Only;
    else
      throw InputError("returns must be 'all', 'first', 'last' or 'only', not '" + r + "'");
  }
  if (given("intensity_range")) f.intensity = rangeOf(d["intensity_range"], "intensity_range");
  if (given("gps_time")) f.gpsTime = rangeOf(d["gps_time"], "gps_time");
  if (given("source_ids")) {
    std::vector<uint16_t> ids;
    for (const py::handle c : d["source_ids"]) {
      const int64_t v = c.cast<int64_t>();
      if (v < 0 || v > 65535) throw InputError("source_ids are point source ids 0 to 65535");
      ids.push_back(uint16_t(v));
    }
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    f.sourceIds = ids;
  }
  checkGpuClip(f);
  return f;
}

Options parseOptions(const py::dict& d) {
  Options o;
  auto get = [&](const char* key) { return d[key]; };
  auto given = [&](const char* key) { return d.contains(key) && !d[key].is_none(); };
  const int64_t width = get("width").cast<int64_t>(), height = get("height").cast<int64_t>();
  if (width < 1 || height < 1) throw InputError("width and height must be at least 1");
  if (width > 65536 || height > 65536) throw InputError("width and height must be at most 65536");
  o.width = uint32_t(width);
  o.height = uint32_t(height);
  o.method = get("method").cast<std::string>();
  o.depth = get("depth").cast<std::string>();
  o.precision = py::str(get("precision")).cast<std::string>();
  const auto bg = get("background").cast<std::vector<int>>();
  if (bg.size() != 3 || *std::min_element(bg.begin(), bg.end()) < 0 ||
      *std::max_element(bg.begin(), bg.end()) > 255)
    throw InputError("background must be three values 0..255 (r, g, b)");
  o.background = packRgba(bg[0], bg[1], bg[2]);
  if (given("frames")) {
    const int64_t frames = get("frames").cast<int64_t>();
    if (frames < 1 || frames > 10000) throw InputError("frames must be 1 to 10000");
    o.frames = uint32_t(frames);
  }
  o.color = get("color").cast<std::string>();
  if (given("color_range")) {
    const auto r = get("color_range").cast<std::vector<double>>();
    if (r.size() != 2 || !(r[0] < r[1])) throw InputError("color_range must be (lo, hi) with lo < hi");
    o.colorRange = ColorRange{r[0], r[1]};
  }
  // --point-size and the rest of the resolve stage, as the CLI's postSettings().
  o.post.pointSize = get("point_size").cast<float>();
  o.post.shape = parsePointShape(get("point_shape").cast<std::string>());
  o.post.sizeMode = parsePointSizeMode(get("point_size_mode").cast<std::string>());
  o.post.maxPointSize = get("point_size_max").cast<float>();
  const int64_t dilate = get("dilate").cast<int64_t>();
  if (dilate < 0) throw InputError("dilate must be 0 or more");
  o.post.dilate = uint32_t(dilate);
  if (get("edl").cast<bool>() || given("edl_strength") || given("edl_radius")) {
    o.post.edlStrength = given("edl_strength") ? get("edl_strength").cast<float>() : 1.0f;
    if (given("edl_radius")) o.post.edlRadius = get("edl_radius").cast<float>();
  }
  validatePostSettings(o.post);
  o.lodOptionsGiven = given("min_node_px") || given("point_budget") || given("gpu_memory");
  if (given("min_node_px")) o.minNodePx = get("min_node_px").cast<double>();
  if (!(o.minNodePx >= 0)) throw InputError("min_node_px must be 0 or more");
  if (given("point_budget")) o.pointBudget = get("point_budget").cast<uint64_t>();
  if (given("gpu_memory")) o.gpuMemory = get("gpu_memory").cast<uint64_t>();
  o.foveation.enabled = get("foveated").cast<bool>();
  if (!o.foveation.enabled && (given("fovea_radius") || given("fovea_periphery")))
    throw InputError("fovea_radius and fovea_periphery need foveated=True");
  if (given("fovea_radius")) o.foveation.radius = get("fovea_radius").cast<double>();
  if (given("fovea_periphery")) o.foveation.periphery = get("fovea_periphery").cast<double>();
  if (!(o.foveation.radius >= 0 && o.foveation.radius <= 1))
    throw InputError("fovea_radius must be between 0 and 1");
  if (!(o.foveation.periphery >= 1) || !std::isfinite(o.foveation.periphery))
    throw InputError("fovea_periphery must be a factor >= 1");
  o.filter = parseFilter(d);
  return o;
}

// The camera of a render: the overview of `bounds` unless `camera` (a dict with eye, target, up, fov,
// near, each optional) says otherwise; target defaults to the center of the bounds, as `--target` does.
Camera resolveCamera(const py::object& camera, const Bounds& bounds, const std::string& source,
                     const Options& o, std::span<const glm::dvec3> framing) {
  checkCoordinateRange(bounds, source);
  py::dict d = camera.is_none() ? py::dict() : camera.cast<py::dict>();
  auto given = [&](const char* key) { return d.contains(key) && !d[key].is_none(); };
  const double fov = given("fov") ? d["fov"].cast<double>() : 60.0;
  if (!(fov > 0 && fov < 180)) throw InputError("camera fov must be between 0 and 180 degrees");
  Camera c = overviewCamera(bounds, double(o.width) / double(o.height), fov, framing);
  if (given("target") && !given("eye")) throw InputError("a camera target needs an eye");
  if (given("eye")) {
    c.eye = vec3(d["eye"], "eye");
    c.target = given("target") ? vec3(d["target"], "target") : bounds.center();
    c.up = given("up") ? vec3(d["up"], "up") : glm::dvec3(0, 0, 1);
  }
  if (given("near")) c.nearW = d["near"].cast<double>();
  if (!(c.nearW >= 0) || !std::isfinite(c.nearW)) throw InputError("camera near must be a number >= 0");
  if (auto problem = findCameraProblem(c))
    throw InputError(given("eye") ? std::string("camera: ") + describeCameraProblem(*problem)
                                  : source + ": no overview camera: " + describeCameraProblem(*problem));
  return c;
}

py::dict cameraDict(const Camera& c) {
  py::dict d;
  d["eye"] = py::make_tuple(c.eye.x, c.eye.y, c.eye.z);
  d["target"] = py::make_tuple(c.target.x, c.target.y, c.target.z);
  d["up"] = py::make_tuple(c.up.x, c.up.y, c.up.z);
  d["fov"] = c.fovY;
  d["near"] = c.nearW;
  return d;
}

py::tuple boundsTuple(const Bounds& b) {
  return py::make_tuple(py::make_tuple(b.min.x, b.min.y, b.min.z), py::make_tuple(b.max.x, b.max.y, b.max.z));
}

// The device, the Renderer and what was uploaded to it, kept between renders.
class Session {
public:
  explicit Session(std::optional<uint32_t> device) {
    gpu::ContextOptions options;
    options.deviceIndex = device;
    options.announce = false;
    context_ = std::make_unique<gpu::Context>(options);
  }
  ~Session() {
    // Scenes and node caches hold buffers of the context: freed before it.
    lod_.reset();
    scene_.reset();
    indexScene_.reset();
    renderer_.reset();
  }

  std::string deviceName() const { return context_->info().name; }

  py::dict render(const py::object& input, const py::object& camera, const py::dict& optionsDict,
                  bool wantDepth, bool wantIndex) {
    const Options o = parseOptions(optionsDict);
    std::lock_guard lock(mutex_);
    if (py::isinstance<Octree>(input)) {
      if (wantDepth || wantIndex)
        throw InputError("return_depth and return_index apply to clouds, not octrees");
      return renderOctree(input.cast<const Octree&>(), camera, o);
    }
    return renderCloud(input.cast<const Cloud&>(), camera, o, wantDepth, wantIndex);
  }

private:
  RenderSettings settings(const Options& o, const std::string& methodName) {
    RenderSettings s;
    s.method = parseMethod(methodName);
    s.depth = parseDepthMode(o.depth);
    s.precision = parsePrecision(o.precision);
    s.background = o.background;
    s.frames = o.frames;
    s.warmup = o.frames > 1 ? 1 : 0; // one frame makes the image; more are timed after a warm-up
    s.post = o.post;
    s.filter = o.filter; // the renderer draws the clip volumes; attribute filters are applied to the cloud
    std::string why;
    if (!Renderer::supports(*context_, s.method, &why)) throw UnsupportedError(why);
    return s;
  }

  Renderer& renderer(const Options& o) {
    if (!renderer_ || renderer_->width() != o.width || renderer_->height() != o.height)
      renderer_ = std::make_unique<Renderer>(*context_, o.width, o.height);
    return *renderer_;
  }

  void checkValidation() const {
    if (context_->validationErrors() > 0)
      throw InternalError("the Vulkan validation layer reported " +
                          std::to_string(context_->validationErrors()) + " error(s)");
  }

  py::array imageArray(const std::vector<uint32_t>& pixels, const Options& o) {
    py::array_t<uint8_t> image({py::ssize_t(o.height), py::ssize_t(o.width), py::ssize_t(4)});
    std::memcpy(image.mutable_data(), pixels.data(), pixels.size() * sizeof(uint32_t));
    return image;
  }

  py::dict result(const std::vector<uint32_t>& pixels, const Options& o, const Camera& c,
                  const FrameStats& st, const std::string& method) {
    py::dict r;
    r["image"] = imageArray(pixels, o);
    r["camera"] = cameraDict(c);
    r["method"] = method;
    r["points"] = st.points;
    r["gpu_ms"] = st.medianMs;
    r["upload_s"] = lastUploadS_;
    r["upload_encode_s"] = lastUpload_.encode;
    r["upload_copy_wait_s"] = lastUpload_.copyWait;
    py::dict steps;
    steps["read"] = lastUpload_.readCpu;
    steps["bounds"] = lastUpload_.boundsCpu;
    steps["words"] = lastUpload_.wordsCpu;
    steps["colors"] = lastUpload_.colorsCpu;
    steps["stage"] = lastUpload_.stageCpu;
    steps["threads"] = lastUpload_.threads;
    steps["allocate_wall"] = lastUpload_.allocate;
    steps["reused_bytes"] = lastUpload_.reusedBytes;
    steps["allocated_bytes"] = lastUpload_.allocatedBytes;
    r["upload_steps_cpu_s"] = steps;
    return r;
  }

  py::dict renderCloud(const Cloud& input, const py::object& camera, const Options& o, bool wantDepth,
                       bool wantIndex) {
    const std::string method = o.method == "auto" ? "atomicmin" : o.method;
    RenderSettings s = settings(o, method);
    const SceneLayout layout = s.method.info().layout;
    if (layout == SceneLayout::Octree)
      throw InputError(method + " draws octrees (" + io::formatList(io::FormatUse::Octree) +
                       "): open one with pointrast.open()");
    if (o.lodOptionsGiven || o.foveation.enabled)
      throw InputError(
          "min_node_px, point_budget, gpu_memory and foveated apply to the LOD methods (octrees)");
    if (s.post.enabled() && s.method.info().output == MethodOutput::ColorOnly)
      throw InputError("point_size, dilate and edl need a compute method; " + method +
                       " keeps no depth per pixel to work on");
    const std::optional<PointFilter> highlight =
        o.filter.hasClip() && o.filter.clipMode == ClipMode::Highlight ? std::optional(o.filter)
                                                                       : std::nullopt;
    // Arrays with RGB colors drawn by a batch method upload straight from the arrays; everything else
    // reads the PointCloud (made from them once).
    const ArrayPoints* arrays = input.arrays();
    if (arrays && !(layout == SceneLayout::Batched && !o.filter.hasAttributeFilter() && !highlight &&
                    (o.color == "auto" || o.color == "rgb") && !o.colorRange && arrays->colorsShowAtOnce()))
      arrays = nullptr;
    std::shared_ptr<PointCloud> drawn;
    if (!arrays) drawn = filtered(input.get(), o.filter);
    const PointCloud& cloud = arrays ? arrays->shape() : *drawn;
    const std::shared_ptr<const void> identity =
        arrays ? std::shared_ptr<const void>(input.arrayPoints()) : std::shared_ptr<const void>(drawn);
    std::optional<DisplayColorMode> colors;
    if (arrays)
      colors = DisplayColorMode{DisplayColorMode::Source::Rgb}; // what displayColorMode() decides for them
    else if (o.color != "auto")
      colors = displayColorMode(cloud, parseColorSource(o.color), o.colorRange);
    else if (o.colorRange)
      throw InputError("color_range applies to color='intensity' and 'elevation'");
    const Camera c = resolveCamera(camera, cloud.bounds, cloud.source, o,
                                   arrays ? arrays->framingSample() : framingSample(cloud));

    std::vector<uint32_t> pixels;
    FrameStats stats;
    std::vector<uint64_t> words;
    if (wantDepth || wantIndex) input.get(); // the index scene reads the PointCloud: made with the GIL
    {
      py::gil_scoped_release release;
      // One uploaded scene per layout and color mode of the cloud last drawn.
      const bool same = scene_ && sceneCloud_.lock() == identity && sceneLayout_ == layout &&
                        sameColors(sceneColors_, colors) && sceneHighlight_ == highlight;
      if (!same) {
        // The new cloud goes into the GPU memory of the one drawn before where it fits (the same size or
        // smaller): no second allocation, and never both scenes' memory at once.
        SceneBuffers previous;
        if (scene_) previous = scene_->takeBuffers();
        scene_.reset();
        UploadOptions upload;
        upload.layout = layout;
        upload.progress = false;
        upload.colors = colors;
        upload.filter = highlight;
        upload.recycle = &previous;
        upload.keepStaging = true;
        const auto start = std::chrono::steady_clock::now();
        scene_ = arrays ? std::make_unique<GpuScene>(*context_, *arrays, upload)
                        : std::make_unique<GpuScene>(*context_, cloud, upload);
        lastUploadS_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        lastUpload_ = scene_->uploadTimes();
        sceneCloud_ = identity;
        sceneLayout_ = layout;
        sceneColors_ = colors;
        sceneHighlight_ = highlight;
      } else {
        lastUploadS_ = 0;
        lastUpload_ = {};
      }
      Renderer& r = renderer(o);
      if (s.frames > 1) {
        // Timed frames as the CLI times them: GPU clocks settled first, frames retimed while a clock
        // change shows in them (render/clock_settle.h).
        auto draw = [&](const RenderSettings& round) { return r.render(*scene_, c, round); };
        settleClocksWith(*context_, s, draw);
        bool settled = true;
        stats = timeSettled(*context_, s, draw, settled);
      } else {
        stats = r.render(*scene_, c, s);
      }
      pixels = r.image();
      if (wantDepth || wantIndex) words = indexWords(input, c, o);
    }
    checkValidation();
    py::dict out = result(pixels, o, c, stats, method);
    if (wantDepth || wantIndex) addDepthIndex(out, words, o, wantDepth, wantIndex);
    return out;
  }

  // The cloud as drawn: the points that pass the attribute filters (a copy kept while the same cloud and
  // filters are drawn), or the cloud itself. The bounds stay the whole cloud's, as the CLI's.
  std::shared_ptr<PointCloud> filtered(const std::shared_ptr<PointCloud>& cloud, const PointFilter& filter) {
    if (!filter.hasAttributeFilter()) return cloud;
    PointFilter attributes = filter;
    attributes.boxes.clear();
    attributes.orientedBoxes.clear();
    attributes.polygons.clear();
    if (filtered_ && filteredFrom_.lock() == cloud && filteredBy_ == attributes) return filtered_;
    requireFilterAttributes(attributes, filterFields(*cloud), cloud->source);
    auto copy = std::make_shared<PointCloud>(*cloud);
    {
      py::gil_scoped_release release;
      applyFilter(*copy, attributes);
    }
    copy->bounds = cloud->bounds;
    filtered_ = copy;
    filteredFrom_ = cloud;
    filteredBy_ = attributes;
    return copy;
  }

  static bool sameColors(const std::optional<DisplayColorMode>& a, const std::optional<DisplayColorMode>& b) {
    if (a.has_value() != b.has_value()) return false;
    return !a || (a->source == b->source && a->lo == b->lo && a->hi == b->hi);
  }

  // The canonical words (depth << 32 | point index) of the closest point at each pixel: atomicmin with
  // float depth on a copy of the cloud whose colors are the points' indices, with the same resolve stage
  // (eye-dome lighting aside: it shades colors only). Every closest-point method picks the same depth.
  std::vector<uint64_t> indexWords(const Cloud& input, const Camera& c, const Options& o) {
    const std::shared_ptr<PointCloud>& made = input.get();
    const PointCloud& cloud = *made;
    if (cloud.size() > kMaxIndexed)
      throw InputError("return_index and return_depth take clouds of at most 16,777,215 points");
    if (!indexScene_ || indexCloud_.lock() != made) {
      indexScene_.reset();
      PointCloud indexed;
      indexed.positions = cloud.positions;
      indexed.scale = cloud.scale;
      indexed.offset = cloud.offset;
      indexed.bounds = cloud.bounds;
      indexed.source = cloud.source;
      indexed.colors.resize(cloud.size());
      for (uint32_t i = 0; i < indexed.colors.size(); ++i)
        indexed.colors[i] = i;
      UploadOptions upload;
      upload.progress = false;
      upload.colors = DisplayColorMode{DisplayColorMode::Source::Rgb};
      indexScene_ = std::make_unique<GpuScene>(*context_, indexed, upload);
      indexCloud_ = made;
    }
    RenderSettings s;
    s.method = pointMethod("atomicmin");
    s.frames = 1;
    s.warmup = 0;
    s.captureWords = true;
    s.post = o.post;
    s.post.edlStrength = 0;
    Renderer& r = renderer(o);
    r.render(*indexScene_, c, s);
    return r.framebufferWords();
  }

  static void addDepthIndex(py::dict& out, const std::vector<uint64_t>& words, const Options& o,
                            bool wantDepth, bool wantIndex) {
    const std::vector<py::ssize_t> shape = {py::ssize_t(o.height), py::ssize_t(o.width)};
    py::array_t<float> depth(shape);
    py::array_t<int64_t> index(shape);
    float* d = depth.mutable_data();
    int64_t* ix = index.mutable_data();
    for (size_t i = 0; i < words.size(); ++i) {
      const uint64_t w = words[i];
      if (w == ~uint64_t(0)) {
        d[i] = std::numeric_limits<float>::infinity();
        ix[i] = -1;
        continue;
      }
      const uint32_t bits = uint32_t(w >> 32);
      std::memcpy(&d[i], &bits, sizeof bits);
      ix[i] = int64_t(w & 0xFFFFFFu);
    }
    if (wantDepth) out["depth"] = depth;
    if (wantIndex) out["index"] = index;
  }

  py::dict renderOctree(const Octree& input, const py::object& camera, const Options& o) {
    lastUploadS_ = 0;
    lastUpload_ = {};
    const lod::OctreeMetadata& meta = input.source->metadata();
    const std::string method = o.method == "auto" ? "lod" : o.method;
    RenderSettings s = settings(o, method);
    if (s.method.info().layout != SceneLayout::Octree)
      throw InputError(method +
                       " draws a loaded cloud; octrees are drawn by the LOD methods (lod, lod-hqs), or "
                       "read whole with pointrast.open(path, lod=False)");
    if (o.depth != "float")
      throw InputError("depth does not apply to " + method +
                       ", which draws an octree's nodes in their stored order");
    if (o.filter.hasAttributeFilter())
      throw InputError("classes, returns, intensity_range, gps_time and source_ids apply to clouds drawn "
                       "from memory; " +
                       method + " draws an octree, which takes clip volumes only");
    if (o.filter.hasClip() && o.filter.clipMode == ClipMode::Highlight)
      throw InputError("clip_mode='highlight' tints the colors of a cloud drawn from memory; " + method +
                       " draws an octree: use 'inside' or 'outside'");
    s.minNodePx = o.minNodePx;
    s.pointBudget = o.pointBudget;
    s.foveation = o.foveation;
    lod::LodOptions options;
    options.gpuBytes = o.gpuMemory;
    if (o.color != "auto")
      options.colorSource = parseColorSource(o.color);
    else if (o.colorRange)
      throw InputError("color_range applies to color='intensity' and 'elevation'");
    options.colorRange = o.colorRange;
    const Camera c = resolveCamera(camera, meta.bounds.empty() ? meta.cube : meta.bounds, meta.source, o,
                                   framingSample(*input.source));
    std::vector<uint32_t> pixels;
    FrameStats stats;
    {
      py::gil_scoped_release release;
      const bool same = lod_ && lodSource_.lock() == input.source && lodColor_ == options.colorSource &&
                        lodGpuBytes_ == options.gpuBytes && sameRange(lodRange_, options.colorRange);
      if (!same) {
        lod_.reset();
        lod_ = std::make_unique<lod::LodScene>(*context_, *input.source, options);
        lodSource_ = input.source;
        lodColor_ = options.colorSource;
        lodRange_ = options.colorRange;
        lodGpuBytes_ = options.gpuBytes;
      }
      Renderer& r = renderer(o);
      stats = r.render(*lod_, c, s);
      pixels = r.image();
    }
    checkValidation();
    return result(pixels, o, c, stats, method);
  }

  static bool sameRange(const std::optional<ColorRange>& a, const std::optional<ColorRange>& b) {
    return a.has_value() == b.has_value() && (!a || (a->lo == b->lo && a->hi == b->hi));
  }

  static constexpr uint64_t kMaxIndexed = 0xFFFFFF; // indices travel in the 24 color bits of a word

  std::mutex mutex_;
  std::unique_ptr<gpu::Context> context_;
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<GpuScene> scene_;
  std::weak_ptr<const void> sceneCloud_; // the PointCloud or the arrays the scene was uploaded from
  SceneLayout sceneLayout_ = SceneLayout::Float;
  std::optional<DisplayColorMode> sceneColors_;
  std::optional<PointFilter> sceneHighlight_;
  std::shared_ptr<PointCloud> filtered_; // the last cloud's points that pass its attribute filters
  std::weak_ptr<PointCloud> filteredFrom_;
  PointFilter filteredBy_;
  double lastUploadS_ = 0; // seconds the last render spent uploading its cloud (0: the upload was reused)
  UploadTimes lastUpload_; // and how: encoding on the host, waiting for copies
  std::unique_ptr<GpuScene> indexScene_;
  std::weak_ptr<PointCloud> indexCloud_;
  std::unique_ptr<lod::LodScene> lod_;
  std::weak_ptr<lod::NodeSource> lodSource_;
  std::optional<DisplayColorMode::Source> lodColor_;
  std::optional<ColorRange> lodRange_;
  uint64_t lodGpuBytes_ = 0;
};

Cloud readCloud(const std::string& path) {
  io::ReadOptions options;
  options.progress = false;
  PointCloud cloud;
  {
    py::gil_scoped_release release;
    cloud = io::readCloud(path, options);
  }
  return Cloud(std::make_shared<PointCloud>(std::move(cloud)));
}

Octree openOctree(const std::string& path) {
  std::unique_ptr<lod::NodeSource> source;
  {
    py::gil_scoped_release release;
    source = io::openNodeSource(path);
  }
  return Octree{std::shared_ptr<lod::NodeSource>(std::move(source))};
}

// What pointrast.open() can make of a path: {"format": name, "cloud": bool, "octree": bool}.
py::dict probe(const std::string& path) {
  const io::FormatInfo* format = io::detectFormat(path);
  if (!format)
    throw InputError(path + ": not a format pointrast reads (" + io::formatList(io::FormatUse::Cloud) +
                     "; octrees: " + io::formatList(io::FormatUse::Octree) + ")");
  py::dict d;
  d["format"] = format->name;
  d["cloud"] = format->read != nullptr;
  d["octree"] = format->openNodes != nullptr;
  d["particles"] = format->content == io::FormatContent::Particles;
  return d;
}

} // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "The compiled half of pointrast: see help(pointrast).";

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const Interrupted&) {
      PyErr_SetNone(PyExc_KeyboardInterrupt);
    } catch (const UnsupportedError& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (const DeviceFault& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (const InternalError& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }
  });

  py::class_<Cloud>(m, "Cloud")
      .def("__len__", [](const Cloud& c) { return c.size(); })
      // Whether the points live only in the arrays they were made from (for tests).
      .def_property_readonly("_arrays_only", [](const Cloud& c) { return c.arrays() != nullptr; })
      .def_property_readonly("source", [](const Cloud& c) { return c.shape().source; })
      .def_property_readonly("bounds", [](const Cloud& c) { return boundsTuple(c.bounds()); })
      .def_property_readonly("scales",
                             [](const Cloud& c) {
                               return py::make_tuple(c.shape().scale.x, c.shape().scale.y, c.shape().scale.z);
                             })
      .def_property_readonly("offsets",
                             [](const Cloud& c) {
                               return py::make_tuple(c.shape().offset.x, c.shape().offset.y,
                                                     c.shape().offset.z);
                             })
      .def("quantized", [](py::object self,
                           int axis) { return positionView(*self.cast<const Cloud&>().get(), axis, self); })
      .def("world", [](const Cloud& c, int axis) { return worldCoordinates(*c.get(), axis); })
      .def("color", [](py::object self,
                       int channel) { return colorView(*self.cast<const Cloud&>().get(), channel, self); })
      .def_property_readonly(
          "has_color",
          [](const Cloud& c) { return c.arrays() ? c.arrays()->hasColor() : c.get()->hasColor(); })
      .def("attribute",
           [](py::object self, const std::string& name) {
             return attributeView(*self.cast<const Cloud&>().get(), name, self);
           })
      .def("point", [](const Cloud& c, int64_t i) {
        if (i < 0 || uint64_t(i) >= c.size()) throw py::index_error("point index out of range");
        const glm::dvec3 p = c.get()->world(uint64_t(i));
        return py::make_tuple(p.x, p.y, p.z);
      });

  py::class_<Octree>(m, "Octree")
      .def_property_readonly("source", [](const Octree& o) { return o.source->metadata().source; })
      .def_property_readonly("format", [](const Octree& o) { return o.source->metadata().format; })
      .def_property_readonly("point_count", [](const Octree& o) { return o.source->metadata().pointCount; })
      .def_property_readonly("bounds",
                             [](const Octree& o) { return boundsTuple(o.source->metadata().bounds); })
      .def_property_readonly("cube", [](const Octree& o) { return boundsTuple(o.source->metadata().cube); })
      .def_property_readonly("spacing", [](const Octree& o) { return o.source->metadata().spacing; })
      .def_property_readonly("depth", [](const Octree& o) { return o.source->metadata().depth; });

  m.def("cloud_from_xyz", [](const py::array& xyz) { return Cloud(std::make_shared<ArrayPoints>(xyz)); });
  m.def("cloud_from_quantized", [](const py::array& x, const py::array& y, const py::array& z,
                                   std::vector<double> scale, std::vector<double> offset) {
    if (scale.size() != 3 || offset.size() != 3)
      throw py::value_error("scales and offsets need three values");
    return Cloud(
        cloudFromQuantized(x, y, z, {scale[0], scale[1], scale[2]}, {offset[0], offset[1], offset[2]}));
  });
  m.def("set_colors", [](Cloud& c, const py::object& r, const py::object& g, const py::object& b) {
    // Arrays take their colors as arrays too; a cloud already made takes them into its own.
    if (ArrayPoints* arrays = c.arrays() ? c.arrayPoints().get() : nullptr)
      arrays->setColors(r, g, b);
    else
      setColors(*c.get(), r, g, b);
  });
  m.def("set_attribute", [](Cloud& c, const std::string& name, const py::object& values) {
    setAttribute(*c.get(), name, values);
  });
  // The cloud as a LAS file (its own scale and offset, colors, intensity, classification, returns, source
  // ids): what pointrast.show() hands to `pointrast serve` for a cloud made in Python.
  m.def("write_las", [](const Cloud& c, const std::string& path) {
    const std::shared_ptr<PointCloud>& cloud = c.get();
    py::gil_scoped_release unlocked;
    io::writeLas(path, *cloud,
                 cloud->size() > 0xFFFFFFFFull ? io::LasFlavor::Las14Pf7 : io::LasFlavor::Las12Pf3);
  });
  m.def("read_cloud", &readCloud);
  m.def("open_octree", &openOctree);
  m.def("probe", &probe);
  m.def("overview_camera", [](const py::tuple& bounds, double aspect, double fov) {
    Bounds b;
    b.min = vec3(bounds[0], "bounds min");
    b.max = vec3(bounds[1], "bounds max");
    if (!(fov > 0 && fov < 180)) throw InputError("camera fov must be between 0 and 180 degrees");
    return cameraDict(overviewCamera(b, aspect, fov));
  });
  // The overview render() uses for a scene: its points framed (a sample of a cloud, an octree's root node).
  m.def("scene_overview_camera", [](const py::object& scene, double aspect, double fov) {
    if (!(fov > 0 && fov < 180)) throw InputError("camera fov must be between 0 and 180 degrees");
    if (py::isinstance<Octree>(scene)) {
      const Octree& o = scene.cast<const Octree&>();
      const lod::OctreeMetadata& meta = o.source->metadata();
      return cameraDict(overviewCamera(meta.bounds.empty() ? meta.cube : meta.bounds, aspect, fov,
                                       framingSample(*o.source)));
    }
    const Cloud& c = scene.cast<const Cloud&>();
    return cameraDict(overviewCamera(c.bounds(), aspect, fov,
                                     c.arrays() ? c.arrays()->framingSample() : framingSample(*c.get())));
  });
  m.def("method_names", [] {
    std::vector<std::string> names;
    for (Method method : allMethods())
      names.push_back(method.name());
    return names;
  });

  py::class_<Session>(m, "Session")
      .def(py::init<std::optional<uint32_t>>(), py::arg("device") = py::none())
      .def_property_readonly("device_name", &Session::deviceName)
      .def("render", &Session::render);
}

} // namespace pointrast::python
