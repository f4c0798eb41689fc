#pragma once
// The station's HTTP server (cpp-httplib), on 127.0.0.1:8360 by default: the
// control API (docs/daemon.md), the console's API (docs/console.md: live
// events, previews, replay, the bank) and the console's pages. Every endpoint
// is one row of one table (control_server.cc), which `GET /api` lists.
// Errors are JSON {"error": "FIELD: reason"}: 400 bad input, 401 token, 403
// another site's page, 404 unknown camera / sprite / path, 409 wrong state,
// 415 a body that is not JSON, 503 not ready. With a token every /api request
// needs `Authorization: Bearer TOKEN`; the pages themselves need none.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "config/station_config.h"

namespace ss {

class StationHost;

struct ControlServerOptions {
  ControlConfig config;  // the config's control section: address, port (0..65535), token
  // The console's pages: served from `web_dir` when set (a source tree's web/, edited live),
  // else by `embedded` (a file's bytes in the copy built into the executable, by its path
  // below web/); neither: no pages. The content type follows the file's extension.
  std::string web_dir;
  std::function<std::optional<std::string_view>(std::string_view path)> embedded;
  int max_event_streams = 16;  // open /api/events connections (>= 0); more get 503
  // Threads serving connections (1..4096): each open connection holds one while it waits for
  // its request (cpp-httplib 0.11). Enough that 500 slow or idle clients leave the API
  // answering: idle, they cost ~10 MB. A slow client keeps its thread for at most the request
  // deadline, and one address holds at most 64 of them (HttpLimits).
  int http_threads = 600;
  std::string
      config_path;  // the daemon's config file (the calibration wizard saves into it); "": none
  // False with "FIELD: reason" lines in `why` (core/option_checks.h) for values out of range.
  bool IsValid(std::string* why) const;
};

class ControlServer {
 public:
  ControlServer(StationHost& host, ControlServerOptions options);
  ~ControlServer();  // Stop()
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  // Binds and serves on its own threads; returns the port (config port 0: a free one).
  // WorkError naming address:port when it cannot bind.
  int Start();
  void Stop();
  std::string url() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ss
