// The README's lists against the product's own: the lists in `--help` are generated from the method and
// format tables, so a README row missing, extra or out of order fails here.
#include <algorithm>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_harness.h"

namespace pointrast::test {

namespace {

std::string readme() {
  const std::filesystem::path path = std::filesystem::path(POINTRAST_SOURCE_DIR) / "README.md";
  return std::filesystem::exists(path) ? slurp(path) : std::string();
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    out.push_back(line);
  return out;
}

// The rows of the Markdown table that follows `heading`: the first cell of each.
std::vector<std::string> tableFirstCells(const std::string& markdown, const std::string& heading) {
  std::vector<std::string> cells;
  bool inSection = false, inTable = false;
  for (const std::string& line : lines(markdown)) {
    if (line.rfind("#", 0) == 0) {
      if (inTable) break;
      inSection = line == heading;
      continue;
    }
    if (!inSection) continue;
    if (line.rfind("|", 0) != 0) {
      if (inTable) break;
      continue;
    }
    if (!inTable) { // the header row, then the separator
      inTable = true;
      continue;
    }
    if (line.rfind("| ---", 0) == 0) continue;
    const size_t end = line.find(" |", 1);
    cells.push_back(line.substr(2, end == std::string::npos ? std::string::npos : end - 2));
  }
  return cells;
}

// Every `name` in backticks of the cells, in order.
std::vector<std::string> backticked(const std::vector<std::string>& cells) {
  std::vector<std::string> names;
  const std::regex name("`([^`]+)`");
  for (const std::string& cell : cells)
    for (std::sregex_iterator it(cell.begin(), cell.end(), name), end; it != end; ++it)
      names.push_back((*it)[1]);
  return names;
}

// The first words of an indented list in help text that follows the line starting with `title`.
std::vector<std::string> helpList(const std::string& help, const std::string& title) {
  std::vector<std::string> names;
  bool in = false;
  for (const std::string& line : lines(help)) {
    if (!in && line.rfind(title, 0) == 0) {
      in = true;
      continue;
    }
    if (!in) continue;
    if (line.rfind("  ", 0) != 0) break;
    std::istringstream words(line);
    std::string first;
    words >> first;
    names.push_back(first);
  }
  return names;
}

} // namespace

TEST(Docs, ReadmeMethodsTableListsEveryPointMethodInTableOrder) {
  const std::string text = readme();
  if (text.empty()) GTEST_SKIP() << "no README.md beside this build";
  CliResult help = runPointrast("render --help");
  ASSERT_EQ(help.exitCode, 0) << help.err;
  const std::vector<std::string> methods = helpList(help.out, "Point methods (--method):");
  ASSERT_GE(methods.size(), 10u) << help.out;
  EXPECT_EQ(backticked(tableFirstCells(text, "## Methods (`--method`)")), methods);
}

TEST(Docs, ReadmeFormatsTableListsEveryFormatInTableOrder) {
  const std::string text = readme();
  if (text.empty()) GTEST_SKIP() << "no README.md beside this build";
  CliResult help = runPointrast("info --help");
  ASSERT_EQ(help.exitCode, 0) << help.err;
  const std::vector<std::string> formats = helpList(help.out, "Formats (");
  ASSERT_GE(formats.size(), 4u) << help.out;
  // The README's rows start with the format's name; rows of what is only written (PNG) have no row in
  // the format table.
  std::vector<std::string> rows;
  for (const std::string& cell : tableFirstCells(text, "## Formats")) {
    const std::string first = cell.substr(0, cell.find(' '));
    if (std::find(formats.begin(), formats.end(), first) != formats.end()) rows.push_back(first);
  }
  EXPECT_EQ(rows, formats);
}

} // namespace pointrast::test
