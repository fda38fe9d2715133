// pointrast profile IN --line x1,y1,x2,y2[,...] --width W [-o PNG] [--las|--laz OUT] [--csv OUT] [filters]
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "base/error.h"
#include "base/progress.h"
#include "cloud/profile.h"
#include "commands.h"
#include "input.h"
#include "io/format_table.h"
#include "io/writer.h"
#include "options.h"
#include "view/profile_tool.h"

namespace pointrast::app {

namespace {

struct ProfileArgs {
  std::string input, line, png, las, laz, csv, size = "1200x500";
  double width = 0;
  bool quiet = false;
  FilterArgs filters;
};

ProfileLine parseLine(const ProfileArgs& a) {
  ProfileLine line;
  line.vertices = view::parseProfileVertices(a.line, "--line");
  if (!(a.width > 0) || !std::isfinite(a.width)) throw InputError("--width must be a positive length");
  line.width = a.width;
  if (!(profileLength(line) > 0)) throw InputError("--line has no length (its vertices coincide)");
  return line;
}

void parseSize(const std::string& text, uint32_t& w, uint32_t& h) {
  unsigned long x = 0, y = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lux%lu%c", &x, &y, &tail) != 2 || x < view::kProfileMinWidth ||
      y < view::kProfileMinHeight || x > view::kProfileMaxSide || y > view::kProfileMaxSide)
    throw InputError("--size expects WxH, 200x120 to 16384x16384, got '" + text + "'");
  w = uint32_t(x);
  h = uint32_t(y);
}

} // namespace

Command addProfile(CLI::App& app) {
  auto a = std::make_shared<ProfileArgs>();
  CLI::App* cmd =
      app.add_subcommand("profile", "Cut a profile (cross section) along a line: PNG, LAS/LAZ, CSV");
  cmd->footer(
      "\nThe profile holds the points whose horizontal (x/y) distance to the line is at most W/2: the\n"
      "distance to the nearest point of the nearest segment, perpendicular to the segment where the foot\n"
      "of the perpendicular falls within it, else to the segment's nearer end. The strip is W wide along\n"
      "every segment, with half-disc caps at the line's ends and round joints. A point's distance along\n"
      "the line is the length of the line up to that nearest point. The filter options apply as well.\n"
      "Outputs: -o a PNG side view (x: distance along the line, y: elevation; nearer points, by their\n"
      "offset to the right of the line's direction, cover farther ones; colors from the file, else the\n"
      "ASPRS classes, else elevation), --las/--laz the kept point records unchanged (LAS, LAZ, COPC input:\n"
      "byte for byte, header counts and bounds for what was kept), --csv one row per point: distance,\n"
      "elevation, x, y, z, intensity, classification, return_number, gps_time (when the file has it),\n"
      "r, g, b (when it has colors, as stored).\n\n"
      "Examples:\n"
      "  pointrast profile autzen.laz --line 636100,849200,637100,849300 --width 4 -o cut.png\n"
      "  pointrast profile city.copc.laz --line 10,10,60,10,60,80 --width 2 --classes 2,6 --csv cut.csv");
  cmd->add_option("IN", a->input,
                  "Point cloud file (" + io::formatList(io::FormatUse::Cloud) +
                      ") or Potree 2.0 octree folder")
      ->required();
  cmd->add_option("--line", a->line, "The polyline, x1,y1,x2,y2[,...] in the file's coordinates")->required();
  cmd->add_option("--width", a->width, "Width of the strip (the points within width/2 of the line)")
      ->required();
  cmd->add_option("-o,--output", a->png, "PNG side view to write");
  cmd->add_option("--size", a->size, "Size of the PNG, WxH pixels")->capture_default_str();
  cmd->add_option("--las", a->las, "LAS file to write with the profile's points");
  cmd->add_option("--laz", a->laz, "LAZ file to write with the profile's points");
  cmd->add_option("--csv", a->csv, "CSV file to write, one row per point");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress lines");
  addFilterOptions(*cmd, a->filters);
  return [a] {
    Progress::setEnabled(!a->quiet);
    const ProfileLine line = parseLine(*a);
    const PointFilter filter = pointFilter(a->filters);
    if (!a->las.empty() && !a->laz.empty()) throw InputError("--las and --laz: give one of them");
    if (a->png.empty() && a->las.empty() && a->laz.empty() && a->csv.empty())
      throw InputError("nothing to write: give -o PNG, --las, --laz or --csv");
    if (!a->las.empty() && std::filesystem::path(a->las).extension() != ".las")
      throw InputError(a->las + ": --las writes a .las file");
    if (!a->laz.empty() && std::filesystem::path(a->laz).extension() != ".laz")
      throw InputError(a->laz + ": --laz writes a .laz file");
    if (!a->png.empty()) {
      uint32_t w = 0, h = 0;
      parseSize(a->size, w, h);
      if (std::filesystem::path(a->png).extension() != ".png")
        throw InputError(a->png + ": -o writes a .png file");
    }
    if (!pathExists(a->input)) throw InputError(a->input + ": no such file or folder");
    view::ProfileRequest request;
    request.input = a->input;
    request.line = line;
    request.filter = filter;
    request.las = a->las.empty() ? a->laz : a->las;
    request.csv = a->csv;
    request.progress = !a->quiet;
    if (!a->png.empty()) parseSize(a->size, request.imageWidth, request.imageHeight);
    const view::ProfileResult c = view::cutProfile(request);
    if (!a->png.empty()) io::writePng(a->png, request.imageWidth, request.imageHeight, c.pixels.data());
    if (!a->quiet)
      std::printf("profile: %s points within %g of a %g long line\n", humanCount(double(c.points)).c_str(),
                  0.5 * line.width, profileLength(line));
    return 0;
  };
}

} // namespace pointrast::app
