#pragma once
// The station's HTTP control API (cpp-httplib), on 127.0.0.1 by default:
//   GET  /api/status                       status as JSON (StatusToJson)
//   GET  /metrics                          Prometheus text format
//   GET  /api/cameras/NAME/preview.jpg     latest frame; ?view=keyed for the matte
//   POST /api/session/start   {"name": S}  starts a capture session
//   POST /api/session/stop                 stops it (its sprites are in the bank on return)
//   POST /api/session/rename  {"name": S}
// Errors are JSON {"error": "..."} naming the field: 400 bad request, 401 token,
// 404 unknown camera or path, 409 session state. With a token configured every
// request needs `Authorization: Bearer TOKEN`.
#include <memory>
#include <string>

#include "core/config.h"

namespace ss {

class Station;

class ControlServer {
 public:
  ControlServer(Station& station, ControlConfig config);
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
