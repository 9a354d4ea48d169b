// `litgs-engine serve`'s HTTP layer (cpp-httplib, included only in http_server.cc): routes, JSON errors,
// limits, and a graceful stop on SIGINT/SIGTERM.
#pragma once

#include "tools/serve/service.h"

namespace litgs::serve {

// Serves until SIGINT or SIGTERM, then finishes the requests in flight and returns 0. Prints
// "serve: listening on http://HOST:PORT" (the bound port, also for --port 0) on stdout once it accepts.
int run_http_server(const ServeOptions& options);

}  // namespace litgs::serve
