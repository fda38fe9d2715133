// Text that came from outside (a file name, a token of a file) made safe to print as part of one line.
#pragma once

#include <string>
#include <string_view>

namespace pointrast {

// The text with every control character escaped (\n, \r, \t, \xNN; DEL as \x7f), so that a message
// naming a file called "a\nb" stays one line on a terminal or in a log. Other bytes, UTF-8 included,
// pass unchanged.
std::string printableLine(std::string_view text);

} // namespace pointrast
