// Small text helpers shared by the layers' messages and reports.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace pointrast {

// "512 KiB", "3.1 MiB", "12.7 GiB": memory sizes in messages and reports.
std::string bytesText(uint64_t bytes);

// Text that came from outside (a file name, a token of a file) made safe to print as part of one line:
// every control character escaped (\n, \r, \t, \xNN; DEL as \x7f), so that a message naming a file
// called "a\nb" stays one line on a terminal or in a log. Other bytes, UTF-8 included, pass unchanged.
std::string printableLine(std::string_view text);

} // namespace pointrast
