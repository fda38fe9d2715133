// The documentation's lists against the product's own: the lists in `--help` are generated from the method
// and format tables, so a row of docs/methods.md or docs/formats.md missing, extra or out of order fails here.
#include <algorithm>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_harness.h"

namespace pointrast::test {

namespace {

std::string doc(const char* file) {
  const std::filesystem::path path = std::filesystem::path(POINTRAST_SOURCE_DIR) / "docs" / file;
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

// The indented lines in help text that follow the line starting with `title`.
std::vector<std::string> helpLines(const std::string& help, const std::string& title) {
  std::vector<std::string> out;
  bool in = false;
  for (const std::string& line : lines(help)) {
    if (!in && line.rfind(title, 0) == 0) {
      in = true;
      continue;
    }
    if (!in) continue;
    if (line.rfind("  ", 0) != 0) break;
    out.push_back(line);
  }
  return out;
}

// The first words of those lines.
std::vector<std::string> helpList(const std::string& help, const std::string& title) {
  std::vector<std::string> names;
  for (const std::string& line : helpLines(help, title)) {
    std::istringstream words(line);
    std::string first;
    words >> first;
    names.push_back(first);
  }
  return names;
}

} // namespace

TEST(Docs, MethodsTableListsEveryPointMethodInTableOrder) {
  const std::string text = doc("methods.md");
  ASSERT_FALSE(text.empty()) << "docs/methods.md is missing";
  CliResult help = runPointrast("render --help");
  ASSERT_EQ(help.exitCode, 0) << help.err;
  const std::vector<std::string> methods = helpList(help.out, "Point methods (--method):");
  ASSERT_GE(methods.size(), 10u) << help.out;
  EXPECT_EQ(backticked(tableFirstCells(text, "## Methods (`--method`)")), methods);
}

TEST(Docs, FormatsTableListsEveryFormatInTableOrder) {
  const std::string text = doc("formats.md");
  ASSERT_FALSE(text.empty()) << "docs/formats.md is missing";
  CliResult help = runPointrast("info --help");
  ASSERT_EQ(help.exitCode, 0) << help.err;
  // The names, which may hold a space ("Potree 2.0"): the first column of the help list, 11 wide.
  std::vector<std::string> formats;
  for (const std::string& line : helpLines(help.out, "Formats (")) {
    std::string name = line.substr(2, 11);
    formats.push_back(name.substr(0, name.find_last_not_of(' ') + 1));
  }
  ASSERT_GE(formats.size(), 4u) << help.out;
  // The table's rows start with the format's name; rows of what is only written (PNG) have no row in
  // the format table.
  std::vector<std::string> rows;
  for (const std::string& cell : tableFirstCells(text, "## Formats"))
    for (const std::string& name : formats)
      if (cell.rfind(name, 0) == 0) rows.push_back(name);
  EXPECT_EQ(rows, formats);
}

} // namespace pointrast::test
