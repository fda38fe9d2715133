#include "report/run_json.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>

#include "base/build_info.h"
#include "base/error.h"

namespace pointrast::report {

nlohmann::json identityJson(const ReportInfo& info, const gpu::DeviceInfo& device, uint64_t deviceLocalBytes,
                            double seconds) {
  nlohmann::json j;
  j["name"] = info.name;
  j["title"] = info.title;
  j["command_line"] = info.commandLine;
  j["date"] = info.date;
  j["commit"] = buildCommit();
  j["wall_seconds"] = seconds;
  j["device"] = {{"name", device.name},          {"type", device.typeName},
                 {"driver", device.driver},      {"vulkan", vulkanVersionText(device.apiVersion)},
                 {"vendor_id", device.vendorId}, {"device_local_bytes", deviceLocalBytes}};
  return j;
}

void writeAtomically(const std::filesystem::path& path, const std::string& content) {
  std::filesystem::path partial = path;
  partial += ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out << content;
    out.close();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(partial, ec);
      throw InputError(path.string() + ": cannot write the file");
    }
  }
  std::error_code ec;
  std::filesystem::rename(partial, path, ec);
  if (ec) {
    std::filesystem::remove(partial, ec);
    throw InputError(path.string() + ": cannot write the file");
  }
}

std::string jsonFileText(const nlohmann::json& j) {
  return j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::string sanitizeName(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      out += char(std::tolower(static_cast<unsigned char>(c)));
    } else if (!out.empty() && out.back() != '-') {
      out += '-';
    }
  }
  while (!out.empty() && out.back() == '-')
    out.pop_back();
  return out.empty() ? "device" : out;
}

std::string formatMs(double ms) {
  if (!(ms > 0) || !std::isfinite(ms)) return "0";
  int decimals = std::clamp(2 - int(std::floor(std::log10(ms))), 0, 9);
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, ms);
  return text;
}

std::string vulkanVersionText(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

std::string utcNow() {
  std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const size_t rank = size_t(std::ceil(std::clamp(p, 0.0, 1.0) * double(values.size())));
  return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

} // namespace pointrast::report
