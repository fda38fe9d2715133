#include "view/web/page.h"

#include <string>
#include <vector>

namespace pointrast::view::web {

namespace {

std::string_view contentType(std::string_view name) {
  if (name.ends_with(".html")) return "text/html; charset=utf-8";
  if (name.ends_with(".js")) return "text/javascript; charset=utf-8";
  if (name.ends_with(".css")) return "text/css; charset=utf-8";
  return "application/octet-stream";
}

struct Entry {
  std::string path;
  PageFile file;
};

const std::vector<Entry>& entries() {
  static const std::vector<Entry> table = [] {
    std::vector<Entry> t;
    for (const EmbeddedFile& f : embeddedPageFiles()) {
      std::string path = f.name == "index.html" ? "/" : "/" + std::string(f.name);
      t.push_back({path, {contentType(f.name), f.data}});
    }
    return t;
  }();
  return table;
}

} // namespace

const PageFile* findPageFile(std::string_view path) {
  for (const Entry& e : entries())
    if (e.path == path) return &e.file;
  return nullptr;
}

bool isPublicPageFile(std::string_view path) {
  return path != "/" && (path.ends_with(".js") || path.ends_with(".css")) && findPageFile(path) != nullptr;
}

} // namespace pointrast::view::web
