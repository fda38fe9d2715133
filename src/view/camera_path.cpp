#include "view/camera_path.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include "base/error.h"
#include "view/navigation.h"

namespace pointrast::view {

namespace {

constexpr const char* kFormat = "pointrast-camera-path";
constexpr int kVersion = 1;

// Cubic Hermite basis on [0, 1]: p(u) = h00 p0 + h10 m0 + h01 p1 + h11 m1.
glm::dvec3 hermite(const glm::dvec3& p0, const glm::dvec3& m0, const glm::dvec3& p1, const glm::dvec3& m1,
                   double u) {
  double u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1;
}

glm::dvec3 vec3(const nlohmann::json& j, const char* key, const std::string& where) {
  const auto found = j.find(key);
  if (found == j.end() || !found->is_array() || found->size() != 3)
    throw InputError(where + ": \"" + key + "\" must be an array of three numbers");
  glm::dvec3 v;
  for (int i = 0; i < 3; ++i) {
    const nlohmann::json& c = (*found)[size_t(i)];
    if (!c.is_number() || !std::isfinite(c.get<double>()))
      throw InputError(where + ": \"" + key + "\" must be an array of three finite numbers");
    v[i] = c.get<double>();
  }
  return v;
}

double number(const nlohmann::json& j, const char* key, const std::string& where) {
  const auto found = j.find(key);
  if (found == j.end() || !found->is_number() || !std::isfinite(found->get<double>()))
    throw InputError(where + ": \"" + key + "\" must be a finite number");
  return found->get<double>();
}

} // namespace

void CameraPath::append(const Camera& camera, double seconds) {
  assert(seconds > 0 && "keyframes must be strictly increasing in time");
  double time = keyframes_.empty() ? 0.0 : keyframes_.back().time + seconds;
  keyframes_.push_back({time, camera});
}

double CameraPath::duration() const {
  return keyframes_.empty() ? 0.0 : keyframes_.back().time - keyframes_.front().time;
}

uint64_t CameraPath::frameCount(double fps) const {
  assert(fps > 0);
  if (keyframes_.empty()) return 0;
  // The small tolerance keeps a path of exactly 5 s at 60 fps at 301 frames despite rounding.
  return uint64_t(std::floor(duration() * fps + 1e-9)) + 1;
}

Camera CameraPath::sample(double time) const {
  assert(!keyframes_.empty() && "sampling an empty path");
  const std::vector<Keyframe>& k = keyframes_;
  double t = std::clamp(k.front().time + time, k.front().time, k.back().time);
  // The segment [k[i].time, k[i+1].time) that holds t; a keyframe's own time returns it exactly.
  auto next = std::upper_bound(k.begin(), k.end(), t, [](double v, const Keyframe& f) { return v < f.time; });
  size_t i = size_t(next - k.begin()) - 1;
  if (k[i].time == t || i + 1 >= k.size()) return k[i].camera;
  double t0 = k[i].time, t1 = k[i + 1].time, span = t1 - t0;
  double u = (t - t0) / span;
  // Tangents per unit of u: the neighbours' slope over their time span, times this segment's span.
  auto tangent = [&](size_t at, auto member) {
    size_t lo = at == 0 ? 0 : at - 1, hi = std::min(at + 1, k.size() - 1);
    return (member(k[hi].camera) - member(k[lo].camera)) / (k[hi].time - k[lo].time) * span;
  };
  auto eye = [](const Camera& c) { return c.eye; };
  auto target = [](const Camera& c) { return c.target; };
  Camera camera = k[i].camera;
  camera.eye = hermite(k[i].camera.eye, tangent(i, eye), k[i + 1].camera.eye, tangent(i + 1, eye), u);
  camera.target =
      hermite(k[i].camera.target, tangent(i, target), k[i + 1].camera.target, tangent(i + 1, target), u);
  glm::dvec3 up = glm::mix(glm::normalize(k[i].camera.up), glm::normalize(k[i + 1].camera.up), u);
  if (glm::length(up) > 1e-9) camera.up = up;
  camera.fovY = k[i].camera.fovY + (k[i + 1].camera.fovY - k[i].camera.fovY) * u;
  return camera;
}

CameraPath orbitPath(const Camera& start, double seconds) {
  assert(seconds > 0);
  constexpr int kSteps = 64; // the one-sided end tangents then stray < 0.1 % from the circle
  CameraPath path;
  glm::dvec3 vertical = glm::normalize(start.up);
  for (int k = 0; k <= kSteps; ++k) {
    Camera c =
        k == 0 ? start : orbit(start, start.target, vertical, 2 * 3.14159265358979323846 * k / kSteps, 0);
    c.up = start.up;
    path.append(c, seconds / kSteps);
  }
  return path;
}

CameraPath CameraPath::parse(const std::string& text, const std::string& name) {
  nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) throw InputError(name + ": not a JSON file");
  if (!j.is_object() || j.value("format", std::string()) != kFormat)
    throw InputError(name + ": not a camera path (\"format\" must be \"" + kFormat + "\")");
  if (!j.contains("version") || !j["version"].is_number_integer() || j["version"].get<int64_t>() != kVersion)
    throw InputError(name + ": unsupported camera path version (this pointrast reads version " +
                     std::to_string(kVersion) + ")");
  const auto frames = j.find("keyframes");
  if (frames == j.end() || !frames->is_array() || frames->empty())
    throw InputError(name + ": \"keyframes\" must be a non-empty array");
  if (frames->size() > kMaxKeyframes)
    throw InputError(name + ": " + std::to_string(frames->size()) + " keyframes, more than the " +
                     std::to_string(kMaxKeyframes) + " a path may hold");
  CameraPath path;
  for (size_t i = 0; i < frames->size(); ++i) {
    const nlohmann::json& f = (*frames)[i];
    std::string where = name + ": keyframe " + std::to_string(i + 1);
    if (!f.is_object()) throw InputError(where + " is not an object");
    Keyframe k;
    k.time = number(f, "time", where);
    k.camera.eye = vec3(f, "eye", where);
    k.camera.target = vec3(f, "target", where);
    k.camera.up = f.contains("up") ? vec3(f, "up", where) : glm::dvec3(0, 0, 1);
    k.camera.fovY = f.contains("fov") ? number(f, "fov", where) : 60.0;
    if (!path.keyframes_.empty() && !(k.time > path.keyframes_.back().time))
      throw InputError(where + ": times must increase strictly from one keyframe to the next");
    try {
      validateCamera(k.camera);
    } catch (const InputError& e) {
      throw InputError(where + ": " + e.what());
    }
    path.keyframes_.push_back(k);
  }
  return path;
}

CameraPath CameraPath::load(const std::filesystem::path& file) {
  std::error_code error;
  auto status = std::filesystem::status(file, error);
  if (error || !std::filesystem::exists(status))
    throw InputError(file.string() + ": no such camera path file");
  if (!std::filesystem::is_regular_file(status)) throw InputError(file.string() + ": not a regular file");
  uint64_t size = std::filesystem::file_size(file, error);
  if (error) throw InputError(file.string() + ": cannot read the file size");
  if (size > kMaxPathFileBytes)
    throw InputError(file.string() + ": " + std::to_string(size) +
                     " bytes, larger than a camera path may be (" + std::to_string(kMaxPathFileBytes) + ")");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open the file");
  std::string text(size, '\0');
  in.read(text.data(), std::streamsize(size));
  if (uint64_t(in.gcount()) != size) throw InputError(file.string() + ": the file changed while being read");
  return parse(text, file.string());
}

std::string CameraPath::toJson() const {
  nlohmann::json frames = nlohmann::json::array();
  for (const Keyframe& k : keyframes_) {
    const Camera& c = k.camera;
    frames.push_back({{"time", k.time},
                      {"eye", {c.eye.x, c.eye.y, c.eye.z}},
                      {"target", {c.target.x, c.target.y, c.target.z}},
                      {"up", {c.up.x, c.up.y, c.up.z}},
                      {"fov", c.fovY}});
  }
  // nlohmann writes doubles with enough digits to read back the same value.
  nlohmann::json j{{"format", kFormat}, {"version", kVersion}, {"keyframes", frames}};
  return j.dump(2) + "\n";
}

void CameraPath::save(const std::filesystem::path& file) const {
  std::filesystem::path partial = file.string() + ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(file.string() + ": cannot create the file");
    std::string text = toJson();
    out.write(text.data(), std::streamsize(text.size()));
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(partial, ignored);
      throw InputError(file.string() + ": write failed");
    }
  }
  std::error_code error;
  std::filesystem::rename(partial, file, error);
  if (error) {
    std::filesystem::remove(partial, error);
    throw InputError(file.string() + ": cannot rename the finished file into place");
  }
}

} // namespace pointrast::view
