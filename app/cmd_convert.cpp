// pointrast convert IN OUT.las|OUT.laz [--order NAME --seed S --las VERSION --drop-waveforms --chunk-size N]
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "base/error.h"
#include "base/progress.h"
#include "commands.h"
#include "input.h"
#include "io/format_table.h"
#include "io/output_check.h"
#include "io/potree/potree.h"
#include "io/writer.h"
#include "options.h"

namespace pointrast::app {

namespace {

struct ConvertArgs {
  std::string input, output, order = "original", lasVersion = "auto";
  uint64_t seed = 1;
  uint32_t chunkSize = 50000;
  int pointFormat = -1;
  bool quiet = false, dropWaveforms = false;
  FilterArgs filters;
  PointFilter filter; // from filters, when the command runs
};

void printNodeStats(const ConvertArgs& a, const io::ClipNodeStats& stats) {
  if (!a.quiet && a.filter.hasClip() && stats.nodes > 0)
    std::printf("%llu of %llu nodes skipped by the clip\n", static_cast<unsigned long long>(stats.skipped),
                static_cast<unsigned long long>(stats.nodes));
}

// A LAS, LAZ or COPC file in its own order and point format: every record byte for byte, with its
// VLRs and EVLRs.
int convertLasFamily(const ConvertArgs& a) {
  io::LasConvertOptions options;
  options.pointFormat = a.pointFormat;
  options.dropWaveforms = a.dropWaveforms;
  options.chunkSize = a.chunkSize;
  options.progress = !a.quiet;
  if (a.lasVersion != "auto") options.versionMinor = a.lasVersion == "1.4" ? 4 : 2;
  io::ClipNodeStats stats;
  options.filter = &a.filter;
  options.nodeStats = &stats;
  const uint64_t points = io::convertLasFile(a.input, a.output, options);
  printNodeStats(a, stats);
  if (!a.quiet) std::printf("%s: %s points\n", a.output.c_str(), humanCount(double(points)).c_str());
  return 0;
}

bool isLasFamily(const io::FormatInfo* format) {
  if (!format) return false;
  const std::string name = format->name;
  return name == "LAS" || name == "LAZ" || name == "COPC";
}

// Whether an octree's classes or return numbers (by metadata.json's ranges) need LAS 1.4's point format 7
// to be exported exactly (formats 0-5 hold classes up to 31 and return numbers up to 7).
bool needsExtendedFormat(const io::PotreeFolderInfo& folder) {
  for (const io::PotreeAttributeInfo& a : folder.attributes) {
    const double max = a.max.empty() ? 0 : a.max[0];
    if ((a.name == "classification" && max > 31) || (a.name == "return number" && max > 7)) return true;
  }
  return false;
}

// What a filter can read of an octree's records: no number of returns, no GPS time.
FilterNeeds octreeFields(const RecordFields& f) {
  FilterNeeds has;
  has.classification = f.classification;
  has.returnNumber = f.returnNumber;
  has.intensity = f.intensity;
  has.pointSourceId = f.pointSourceId;
  return has;
}

// An octree (a Potree 2.0 folder, or an EPT dataset when filtering) in its own order: streamed node by
// node, every integer, scale/offset and 16-bit color as the octree stores it.
int convertOctree(const ConvertArgs& a, const io::FormatInfo& format) {
  std::unique_ptr<lod::NodeSource> source = format.openNodes(a.input);
  requireFilterAttributes(a.filter, octreeFields(source->metadata().fields), source->metadata().source);
  io::LasFlavor flavor = lasFlavorFor(a.output, source->metadata().pointCount);
  if (a.lasVersion == "1.4" || (a.lasVersion == "auto" && format.openNodes == &io::openPotree &&
                                needsExtendedFormat(io::probePotree(a.input))))
    flavor = io::LasFlavor::Las14Pf7;
  io::ClipNodeStats stats;
  const uint64_t points = io::writeLasFromOctree(a.output, *source, flavor, !a.quiet, &a.filter, &stats);
  printNodeStats(a, stats);
  if (!a.quiet) std::printf("%s: %s points\n", a.output.c_str(), humanCount(double(points)).c_str());
  return 0;
}

} // namespace

// LAS (or LAZ, by the extension) 1.2 point format 3 unless the count needs LAS 1.4's 64-bit counts (or
// --las 1.4 asks for it).
io::LasFlavor lasFlavorFor(const std::string& output, uint64_t points) {
  const std::filesystem::path ext = std::filesystem::path(output).extension();
  if (ext != ".las" && ext != ".laz")
    throw InputError(output + ": only LAS and LAZ output (.las, .laz) is supported");
  return points > 0xFFFFFFFFull ? io::LasFlavor::Las14Pf7 : io::LasFlavor::Las12Pf3;
}

Command addConvert(CLI::App& app) {
  auto a = std::make_shared<ConvertArgs>();
  CLI::App* cmd =
      app.add_subcommand("convert", "Read a point cloud, optionally reorder it, write LAS or LAZ");
  cmd->footer(
      "\nOrders (the 2021 paper's vertex orders): original, morton (Z-order over the cubic bounds, 21 bits\n"
      "per axis), shuffled (random permutation), shuffled-morton (Morton, then runs of 128 points\n"
      "shuffled as wholes). OUT ending in .laz is written compressed (LASzip chunks), else as LAS.\n"
      "A LAS, LAZ or COPC file in its original order is converted losslessly: every point record byte\n"
      "for byte in its own point format (16-bit colors, NIR, GPS time, flags, extra bytes...), its VLRs\n"
      "and EVLRs. Waveform formats (4, 5, 9, 10) are refused unless --drop-waveforms. --point-format\n"
      "or --las 1.2/1.4 (formats 0-3 / 6-8) converts the records, refusing what the format cannot hold.\n"
      "Other inputs and reordered clouds: LAS 1.2 point format 3, or 1.4 format 7 with\n"
      "--las 1.4 or when the cloud has more than 4,294,967,295 points.\n"
      "A Potree 2.0 octree (its folder or metadata.json) is exported exactly: its integers, scale/offset\n"
      "and 16-bit colors, node after node (LAS 1.4 format 7 when its classes or return numbers need it);\n"
      "one that `lod` built from LAS/LAZ files in the inputs' point format with every attribute and the\n"
      "extra bytes (its records byte for byte when built with --no-color-filter).\n\n"
      "Examples:\n  pointrast convert scan.ply scan_morton.las --order morton\n"
      "  pointrast convert lion.copc.laz lion.laz\n"
      "  pointrast convert octree/ all.laz\n"
      "  pointrast convert city.laz ground.laz --classes 2 --clip-box 500,200,0,900,600,100\n\n"
      "Filters keep exactly the points that pass them, records unchanged; the header's counts and bounds\n"
      "describe what was written. Octrees and COPC files skip whole nodes outside the clip.");
  cmd->add_option("IN", a->input,
                  "Point cloud file (" + io::formatList(io::FormatUse::Cloud) +
                      ") or Potree 2.0 octree folder")
      ->required();
  cmd->add_option("OUT", a->output, "LAS or LAZ file to write")->required();
  cmd->add_option("--order", a->order, "Vertex order")->capture_default_str();
  cmd->add_option("--seed", a->seed, "Seed of the shuffled orders")->capture_default_str();
  cmd->add_option("--las", a->lasVersion, "LAS version to write: auto, 1.2 or 1.4")->capture_default_str();
  cmd->add_option("--point-format", a->pointFormat,
                  "LAS/LAZ/COPC input: the point format to write (0-3, 6-8; default: the input's)");
  cmd->add_option("--chunk-size", a->chunkSize, "Points per LAZ chunk")->capture_default_str();
  cmd->add_flag("--drop-waveforms", a->dropWaveforms,
                "Convert waveform point formats (4, 5, 9, 10) without their wave packets");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress lines");
  addFilterOptions(*cmd, a->filters);
  return [a] {
    Progress::setEnabled(!a->quiet);
    if (a->lasVersion != "auto" && a->lasVersion != "1.2" && a->lasVersion != "1.4")
      throw InputError("--las expects auto, 1.2 or 1.4");
    lasFlavorFor(a->output, 0);
    if (!pathExists(a->input)) throw InputError(a->input + ": no such file or folder");
    io::checkOutputTarget(a->output, "OUT");
    const io::FormatInfo* format = io::detectFormat(a->input);
    if (a->chunkSize == 0) throw InputError("--chunk-size must be at least 1 point");
    a->filter = pointFilter(a->filters);
    if (a->order == "original" && format && format->openNodes == &io::openPotree)
      return convertOctree(*a, *format);
    if (a->pointFormat != -1 &&
        (a->pointFormat < 0 || !((a->pointFormat <= 3) || (a->pointFormat >= 6 && a->pointFormat <= 8))))
      throw InputError("--point-format expects 0, 1, 2, 3, 6, 7 or 8");
    if (a->order == "original" && isLasFamily(format)) return convertLasFamily(*a);
    if (a->order == "original" && format && format->openNodes && a->filter.active())
      return convertOctree(*a, *format);
    if (a->pointFormat != -1)
      throw InputError("--point-format applies to LAS, LAZ and COPC inputs in their original order");
    InputSpec spec;
    spec.source = a->input;
    spec.order = parseOrder(a->order);
    spec.seed = a->seed;
    spec.progress = !a->quiet;
    PointCloud cloud = loadInput(spec);
    requireFilterAttributes(a->filter, filterFields(cloud), cloud.source);
    applyFilter(cloud, a->filter);
    io::LasFlavor flavor = lasFlavorFor(a->output, cloud.size());
    if (a->lasVersion == "1.4") flavor = io::LasFlavor::Las14Pf7;
    if (a->lasVersion == "1.2" && flavor == io::LasFlavor::Las14Pf7)
      throw InputError("LAS 1.2 cannot hold more than 4,294,967,295 points; use --las 1.4");
    io::writeLas(a->output, cloud, flavor);
    if (!a->quiet)
      std::printf("%s: %s points\n", a->output.c_str(), humanCount(double(cloud.size())).c_str());
    return 0;
  };
}

} // namespace pointrast::app
