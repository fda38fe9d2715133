// pointrast: render huge point clouds by software rasterization in compute shaders.
// Thin on purpose: parsing and wiring only; the work lives in src/.
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include <CLI/CLI.hpp>

#include "base/build_info.h"
#include "base/error.h"
#include "commands.h"
#include "gpu/vulkan_api.h"

int main(int argc, char** argv) {
  using namespace pointrast;
  CLI::App app{"pointrast: renders billions of points and particles by software rasterization in compute "
               "shaders (Vulkan 1.3; any GPU, or the CPU through lavapipe).\n\n"
               "Examples:\n"
               "  pointrast render -o demo.png                       # built-in demo scene\n"
               "  pointrast render cloud.las -o out.png --json       # a point cloud file, timing as JSON\n"
               "  pointrast info cloud.las                           # what a file holds\n"
               "  pointrast generate terrain --points 10M -o t.las   # a synthetic scene as LAS\n"
               "  pointrast convert in.ply out.las --order morton    # reorder and write LAS\n",
               "pointrast"};
  app.require_subcommand(1);
  app.fallthrough(false);
  app.set_version_flag("--version", std::string("pointrast 0.1.0 (") + buildCommit() + ")");
  app.footer("Run `pointrast COMMAND --help` for a command's options. Exit status: 0 success, 1 error.");

  app::Command info = app::addInfo(app);
  app::Command render = app::addRender(app);
  app::Command convert = app::addConvert(app);
  app::Command generate = app::addGenerate(app);
  app::Command bench = app::addBench(app);
  app::Command benchIo = app::addBenchIo(app, argc, argv);
  app::Command view = app::addView(app);
  app::Command lod = app::addLod(app);
  app::Command serve = app::addServe(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string which = app.get_subcommands().empty() ? "" : " " + app.get_subcommands().front()->get_name();
    std::fprintf(stderr, "pointrast: %s (see `pointrast%s --help`)\n", e.what(), which.c_str());
    return 1;
  }

  try {
    for (CLI::App* sub : app.get_subcommands()) {
      if (sub->get_name() == "info") return info();
      if (sub->get_name() == "render") return render();
      if (sub->get_name() == "convert") return convert();
      if (sub->get_name() == "generate") return generate();
      if (sub->get_name() == "bench") return bench();
      if (sub->get_name() == "bench-io") return benchIo();
      if (sub->get_name() == "view") return view();
      if (sub->get_name() == "lod") return lod();
      if (sub->get_name() == "serve") return serve();
    }
    return 1;
  } catch (const InputError& e) {
    std::fprintf(stderr, "pointrast: %s\n", e.what());
  } catch (const UnsupportedError& e) {
    std::fprintf(stderr, "pointrast: %s\n", e.what());
  } catch (const DeviceFault& e) {
    std::fprintf(stderr, "pointrast: %s\n", e.what());
  } catch (const gpu::VulkanError& e) {
    std::fprintf(stderr, "pointrast: %s\n", e.what());
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "pointrast: out of host memory\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pointrast: %s\n", e.what());
  }
  return 1;
}
