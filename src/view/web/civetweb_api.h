// civetweb entry points, loaded at run time from libcivetweb.so.1 (dlopen) rather than linked, as GLFW is
// (view/desktop/glfw_api.h): a pointrast binary then starts where civetweb is not installed, and only
// `serve` asks for it. The library is looked up by the loader's rules, then beside the executable (a
// GPU machine gets a copy there). Every function used is listed here once.
#pragma once

#include <civetweb.h>

// clang-format off
#define PR_CIVETWEB_FUNCTIONS(X) \
  X(mg_init_library) X(mg_check_feature) X(mg_start) X(mg_stop) X(mg_set_request_handler) \
  X(mg_set_websocket_handler) X(mg_get_request_info) X(mg_get_header) X(mg_get_var) X(mg_get_cookie) \
  X(mg_write) X(mg_websocket_write) X(mg_get_server_ports) X(mg_set_user_connection_data) \
  X(mg_get_user_connection_data) X(mg_version)
// clang-format on

namespace pointrast::view::civetweb {

#define PR_CIVETWEB_DECLARE(name) extern decltype(&::name) name;
PR_CIVETWEB_FUNCTIONS(PR_CIVETWEB_DECLARE)
#undef PR_CIVETWEB_DECLARE

// Opens libcivetweb.so.1 and loads every function. Throws UnsupportedError naming the package when the
// library is missing or lacks WebSocket support. Idempotent.
void load();

} // namespace pointrast::view::civetweb
