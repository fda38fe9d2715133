// Small text helpers shared by the layers' messages and reports.
#pragma once

#include <cstdint>
#include <string>

namespace pointrast {

// "512 KiB", "3.1 MiB", "12.7 GiB": memory sizes in messages and reports.
std::string bytesText(uint64_t bytes);

} // namespace pointrast
