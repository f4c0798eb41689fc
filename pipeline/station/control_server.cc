#include "pipeline/station/control_server.h"

#include <thread>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/log.h"
#include "pipeline/station/station.h"
#include "pipeline/station/station_status.h"

namespace ss {
namespace {

void Reply(httplib::Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_content(body.dump(2) + "\n", "application/json");
}

void ReplyError(httplib::Response& res, int status, const std::string& message) {
  Reply(res, status, {{"error", message}});
}

// The "name" of a JSON body; InputError naming the field when it is missing or not text.
std::string NameFromBody(const httplib::Request& req, bool required) {
  if (req.body.empty()) {
    if (required) throw InputError("body", "expected JSON {\"name\": \"...\"}");
    return "";
  }
  nlohmann::json body;
  try {
    body = nlohmann::json::parse(req.body);
  } catch (const nlohmann::json::exception& e) {
    throw InputError("body", std::string("not valid JSON: ") + e.what());
  }
  if (!body.is_object()) throw InputError("body", "expected a JSON object");
  for (const auto& [key, value] : body.items()) {
    if (key != "name") throw InputError(key, "unknown field (the request takes \"name\")");
  }
  if (!body.contains("name")) {
    if (required) throw InputError("name", "missing");
    return "";
  }
  if (!body["name"].is_string()) throw InputError("name", "expected text, got " + body["name"].dump());
  return body["name"].get<std::string>();
}

}  // namespace

struct ControlServer::Impl {
  Station* station = nullptr;
  ControlConfig config;
  httplib::Server server;
  std::thread thread;
  int port = 0;

  // Runs a handler; InputError becomes 400 (or `input_status`), anything else 500.
  template <typename F>
  void Guard(httplib::Response& res, int input_status, F&& f) {
    try {
      f();
    } catch (const InputError& e) {
      ReplyError(res, input_status, e.what());
    } catch (const std::exception& e) {
      Log("station.control")->error("{}", e.what());
      ReplyError(res, 500, e.what());
    }
  }

  void Routes() {
    server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
      if (config.token.empty()) return httplib::Server::HandlerResponse::Unhandled;
      const std::string expected = "Bearer " + config.token;
      if (req.get_header_value("Authorization") != expected) {
        res.set_header("WWW-Authenticate", "Bearer");
        ReplyError(res, 401, "Authorization: this station needs \"Authorization: Bearer TOKEN\" (control.token)");
        return httplib::Server::HandlerResponse::Handled;
      }
      return httplib::Server::HandlerResponse::Unhandled;
    });
    server.Get("/", [](const httplib::Request&, httplib::Response& res) {
      Reply(res, 200, {{"service", "spritestation"},
                       {"endpoints", {"GET /api/status", "GET /metrics", "GET /api/cameras/NAME/preview.jpg?view=raw|keyed",
                                      "POST /api/session/start {\"name\": S}", "POST /api/session/stop",
                                      "POST /api/session/rename {\"name\": S}"}}});
    });
    server.Get("/api/status", [this](const httplib::Request&, httplib::Response& res) {
      Guard(res, 400, [&] {
        StationStatus status = station->Status();
        status.control_url = Url();
        Reply(res, 200, StatusToJson(status));
      });
    });
    server.Get("/metrics", [this](const httplib::Request&, httplib::Response& res) {
      Guard(res, 400, [&] { res.set_content(StatusToPrometheus(station->Status()), "text/plain; version=0.0.4"); });
    });
    server.Get(R"(/api/cameras/([^/]+)/preview\.jpg)", [this](const httplib::Request& req, httplib::Response& res) {
      const std::string view = req.has_param("view") ? req.get_param_value("view") : "raw";
      if (view != "raw" && view != "keyed") {
        ReplyError(res, 400, "view: expected raw or keyed, got \"" + view + "\"");
        return;
      }
      Guard(res, 404, [&] {
        const auto jpeg = station->PreviewJpeg(req.matches[1], view == "keyed");
        if (!jpeg) {
          ReplyError(res, 503, "camera \"" + std::string(req.matches[1]) + "\" has delivered no frame yet");
          return;
        }
        res.set_content(reinterpret_cast<const char*>(jpeg->data()), jpeg->size(), "image/jpeg");
      });
    });
    server.Post("/api/session/start", [this](const httplib::Request& req, httplib::Response& res) {
      Guard(res, 400, [&] {
        std::string name = NameFromBody(req, false);
        if (name.empty()) name = "session";
        try {
          Reply(res, 200, SessionToJson(station->StartSession(name)));
        } catch (const InputError& e) {
          ReplyError(res, std::string(e.what()).rfind("name", 0) == 0 ? 400 : 409, e.what());
        }
      });
    });
    server.Post("/api/session/stop", [this](const httplib::Request&, httplib::Response& res) {
      Guard(res, 409, [&] { Reply(res, 200, SessionToJson(station->StopSession())); });
    });
    server.Post("/api/session/rename", [this](const httplib::Request& req, httplib::Response& res) {
      Guard(res, 400, [&] {
        const std::string name = NameFromBody(req, true);
        try {
          Reply(res, 200, SessionToJson(station->RenameSession(name)));
        } catch (const InputError& e) {
          ReplyError(res, std::string(e.what()).rfind("name", 0) == 0 ? 400 : 409, e.what());
        }
      });
    });
    server.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
      if (!res.body.empty()) return;
      if (res.status == 404) {
        ReplyError(res, 404, "no such endpoint: " + req.method + " " + req.path + " (GET / lists them)");
      } else if (res.status == 405 || res.status == 400) {
        ReplyError(res, res.status, "malformed request: " + req.method + " " + req.path);
      }
    });
  }

  std::string Url() const {
    const bool v6 = config.address.find(':') != std::string::npos;
    return "http://" + (v6 ? "[" + config.address + "]" : config.address) + ":" + std::to_string(port);
  }
};

ControlServer::ControlServer(Station& station, ControlConfig config) : impl_(std::make_unique<Impl>()) {
  impl_->station = &station;
  impl_->config = std::move(config);
  impl_->Routes();
}

ControlServer::~ControlServer() { Stop(); }

int ControlServer::Start() {
  Impl& s = *impl_;
  const std::string host = s.config.address == "localhost" ? "127.0.0.1" : s.config.address;
  if (s.config.port == 0) {
    s.port = s.server.bind_to_any_port(host);
  } else {
    s.port = s.server.bind_to_port(host, s.config.port) ? s.config.port : -1;
  }
  if (s.port <= 0) {
    throw WorkError("control " + s.config.address + ":" + std::to_string(s.config.port),
                    "cannot listen there (address not on this machine, or the port is taken)");
  }
  s.thread = std::thread([&s] { s.server.listen_after_bind(); });
  Log("station.control")->info("control API on {}", s.Url());
  return s.port;
}

void ControlServer::Stop() {
  Impl& s = *impl_;
  if (s.thread.joinable()) {
    s.server.stop();
    s.thread.join();
  }
}

std::string ControlServer::url() const { return impl_->Url(); }

}  // namespace ss
