// The page the browser viewer serves: HTML, JavaScript and CSS from src/view/web/page/, embedded in the
// binary at build time (cmake/embed_files.cmake). No CDN, no build step, nothing read from disk at run time.
#pragma once

#include <span>
#include <string_view>

namespace pointrast::view::web {

struct EmbeddedFile {
  std::string_view name; // file name in src/view/web/page/
  std::string_view data;
};
// Generated.
std::span<const EmbeddedFile> embeddedPageFiles();

struct PageFile {
  std::string_view contentType;
  std::string_view body;
};
// The file a URL path names ("/" is index.html, "/app.js", ...), or nothing: no other path is served.
const PageFile* findPageFile(std::string_view path);

// The page's script and style sheet (not the page itself): files that hold no data and may load without the
// access token.
bool isPublicPageFile(std::string_view path);

} // namespace pointrast::view::web
