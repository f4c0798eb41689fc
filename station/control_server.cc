#include "station/control_server.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>
#include <vector>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/error_kinds.h"
#include "core/log.h"
#include "core/option_checks.h"
#include "core/posix.h"
#include "station/api_part.h"
#include "station/console_animations.h"
#include "station/console_bank.h"
#include "station/console_calibration.h"
#include "station/console_events.h"
#include "station/console_labels.h"
#include "station/http_server.h"
#include "station/station.h"
#include "station/station_host.h"
#include "station/station_status.h"

namespace ss {
namespace {

namespace fs = std::filesystem;
using api::IntParam;
using api::ObjectBody;
using api::PathId;
using api::Reply;
using api::ReplyError;
using api::Route;
using httplib::Request;
using httplib::Response;

// HTTP worker threads run below capture and keying (core/posix.h): a preview encode or a
// bank page never takes a core from capture; background bank work runs below them.
class NiceThreadPool : public httplib::TaskQueue {
 public:
  explicit NiceThreadPool(size_t n) : pool_(n) {}
  void enqueue(std::function<void()> fn) override {
    pool_.enqueue([fn = std::move(fn)] {
      thread_local const bool niced = [] {
        SetThisThreadNice(kNiceHttp);
        return true;
      }();
      (void)niced;
      fn();
    });
  }
  void shutdown() override { pool_.shutdown(); }

 private:
  httplib::ThreadPool pool_;
};

// A session name from {"name": S}; "" when absent and not required.
std::string NameFromBody(const Request& req, bool required) {
  return api::ParseSessionName(ObjectBody(req, api::kSessionFields), required, req.body.empty());
}

std::string Lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return text;
}

// "host" of "host:port" / "[v6]:port", lower-cased.
std::string HostName(const std::string& host_port) {
  const std::string host = Lower(host_port);
  if (!host.empty() && host[0] == '[') return host.substr(1, host.find(']') - 1);
  const size_t colon = host.rfind(':');
  return colon == std::string::npos ? host : host.substr(0, colon);
}

// The page a request's (decoded) path names, relative to web/ ("/" is "index.html"): "." and
// empty segments dropped, ".." taking the one before. Nullopt for a path that climbs out of
// the pages or holds anything but letters, digits and "_-./" (a backslash, a NUL, a byte of
// an overlong UTF-8 sequence): such a path names no page, whatever the folder holds.
std::optional<std::string> PagePath(std::string_view request_path) {
  if (request_path.empty() || request_path[0] != '/') return std::nullopt;
  std::vector<std::string_view> segments;
  size_t at = 1;
  while (at <= request_path.size()) {
    size_t end = request_path.find('/', at);
    if (end == std::string_view::npos) end = request_path.size();
    const std::string_view segment = request_path.substr(at, end - at);
    at = end + 1;
    for (const char c : segment) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.')
        return std::nullopt;
    }
    if (segment.empty() || segment == ".") continue;
    if (segment == "..") {
      if (segments.empty()) return std::nullopt;
      segments.pop_back();
      continue;
    }
    segments.push_back(segment);
  }
  if (segments.empty()) return "index.html";
  std::string path;
  for (const std::string_view segment : segments) {
    if (!path.empty()) path += '/';
    path += segment;
  }
  return path;
}

// Whether the Authorization header carries `token`, in a time that does not depend on where
// the two first differ (nor on the token's content: only its length).
bool CarriesToken(const std::string& authorization, const std::string& token) {
  static constexpr std::string_view kScheme = "Bearer ";
  const std::string_view given = authorization;
  if (given.size() != kScheme.size() + token.size()) return false;
  unsigned char diff = 0;
  for (size_t i = 0; i < given.size(); ++i) {
    const char want = i < kScheme.size() ? kScheme[i] : token[i - kScheme.size()];
    diff |= static_cast<unsigned char>(given[i] ^ want);
  }
  return diff == 0;
}

const char* ContentTypeOf(const fs::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  if (ext == ".ico") return "image/x-icon";
  if (ext == ".json") return "application/json";
  return "application/octet-stream";
}

}  // namespace

struct ControlServer::Impl {
  StationHost* host = nullptr;
  ControlServerOptions options;
  HttpServer server;  // cpp-httplib's, with the limits per client and per request (http_server.h)
  std::thread thread;
  int port = 0;
  std::unique_ptr<ConsoleEvents> events;
  int status_listener = 0;  // the host's status listener telling `events` (0: none)
  std::vector<Route> routes;
  std::vector<std::regex> route_patterns;         // routes[i]'s pattern, compiled
  std::vector<std::unique_ptr<api::Part>> parts;  // the API's parts in files of their own

  // Every part of the API that lives in a file of its own: one line each.
  void MakeParts() {
    api::Context context;
    context.host = host;
    context.station = [this] { return station(); };
    context.config_path = options.config_path;
    context.status_changed = [this] { events->Changed(); };
    parts.push_back(std::make_unique<ConsoleCalibration>(context));
    parts.push_back(std::make_unique<ConsoleLabels>(context));
    parts.push_back(std::make_unique<ConsoleAnimations>(context));
  }

  std::shared_ptr<Station> station() const {
    std::shared_ptr<Station> s = host->current();
    if (!s) throw WorkError("station", "not running");
    return s;
  }

  // The station's status, with the HTTP server's own figures.
  StationStatus Status() const {
    StationStatus status = station()->Status();
    status.control_url = Url();
    const HttpCounters http = server.counters();
    status.control_connections_open = http.connections_open;
    status.control_connections_refused = http.connections_refused;
    status.control_requests_timed_out = http.requests_timed_out;
    return status;
  }

  nlohmann::json StatusJson() const {
    nlohmann::json j = StatusToJson(Status());
    j.update(host->ModeJson());
    for (const auto& part : parts) part->AddStatus(j);
    return j;
  }

  // Runs a handler: the error's kind picks the status (core/error_kinds.h).
  template <typename F>
  static void Guard(Response& res, F&& f) {
    try {
      f();
    } catch (const NotFoundError& e) {
      ReplyError(res, 404, e.what());
    } catch (const ConflictError& e) {
      ReplyError(res, 409, e.what());
    } catch (const InputError& e) {
      ReplyError(res, 400, e.what());
    } catch (const std::exception& e) {
      Log("station.control")->error("{}", e.what());
      ReplyError(res, 500, e.what());
    }
  }

  // What every /api request must pass before its handler: the host it was sent to (a loopback
  // station without a token answers only to loopback names: no DNS rebinding), the page that sent
  // it (another site's page may not act) and the token. (The body is read after this: a POST's
  // JSON type is checked by its handler's wrapper.)
  httplib::Server::HandlerResponse Admit(const Request& req, Response& res) {
    // A body whose end is ambiguous is refused before anything else (http_server.h).
    if (const std::string why = HttpServer::AmbiguousFraming(req); !why.empty()) {
      ReplyError(res, 400, why + " (where the body ends is ambiguous)");
      return httplib::Server::HandlerResponse::Handled;
    }
    const bool api =
        req.path == "/metrics" || req.path == "/api" || req.path.rfind("/api/", 0) == 0;
    if (!api) return httplib::Server::HandlerResponse::Unhandled;
    const ControlConfig& config = options.config;
    const std::string host = HostName(req.get_header_value("Host"));
    if (config.token.empty() && !host.empty() && !IsLoopbackAddress(host)) {
      ReplyError(res, 403,
                 "Host: \"" + host +
                     "\" is not a loopback name; this station (no control.token) answers only "
                     "to localhost and 127.0.0.1");
      return httplib::Server::HandlerResponse::Handled;
    }
    const std::string origin = req.get_header_value("Origin");
    if (!origin.empty()) {
      const size_t scheme = origin.find("://");
      const std::string origin_host =
          scheme == std::string::npos ? origin : origin.substr(scheme + 3);
      if (Lower(origin_host) != Lower(req.get_header_value("Host"))) {
        ReplyError(res, 403, "Origin: a page of " + origin + " may not use this station's API");
        return httplib::Server::HandlerResponse::Handled;
      }
    }
    if (!config.token.empty() &&
        !CarriesToken(req.get_header_value("Authorization"), config.token)) {
      res.set_header("WWW-Authenticate", "Bearer");
      ReplyError(
          res, 401,
          "Authorization: this station needs \"Authorization: Bearer TOKEN\" (control.token)");
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  }

  // The console's static files: only the pages' own set (the files the build embeds), read
  // from the web folder when one is given, else from the embedded copy. A path that names
  // anything else, however spelled, is not served.
  bool ServeWebFile(const std::string& request_path, Response& res) {
    if (!options.embedded) return false;
    const std::optional<std::string> path = PagePath(request_path);
    if (!path) return false;
    const std::optional<std::string_view> embedded = options.embedded(*path);
    if (!embedded) return false;
    if (!options.web_dir.empty()) {
      std::ifstream in(fs::path(options.web_dir) / *path, std::ios::binary);
      if (!in) return false;
      std::ostringstream bytes;
      bytes << in.rdbuf();
      res.set_content(bytes.str(), ContentTypeOf(*path));
    } else {
      res.set_content(std::string(*embedded), ContentTypeOf(*path));
    }
    res.set_header("Cache-Control", "no-cache");
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header(
        "Content-Security-Policy",
        "default-src 'self'; img-src 'self' data: blob:; style-src 'self'; script-src 'self'; "
        "connect-src 'self'; frame-ancestors 'none'");
    res.status = 200;
    return true;
  }

  void Events(const Request&, Response& res) {
    if (events->connections() >= static_cast<uint64_t>(options.max_event_streams)) {
      ReplyError(res, 503,
                 "events: " + std::to_string(options.max_event_streams) +
                     " event streams are open already (close a console tab)");
      return;
    }
    auto stream = std::make_shared<ConsoleEvents::Stream>(*events);
    HttpServer::CountApart();  // limited by max_event_streams, not the connection limits
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Accel-Buffering", "no");
    res.set_chunked_content_provider("text/event-stream",
                                     [stream](size_t, httplib::DataSink& sink) {
                                       const std::string text = stream->Next();
                                       if (text.empty()) {
                                         sink.done();
                                         return true;
                                       }
                                       return sink.write(text.data(), text.size());
                                     });
  }

  void Preview(const Request& req, Response& res) {
    const std::string view = req.has_param("view") ? req.get_param_value("view") : "raw";
    if (view != "raw" && view != "keyed")
      throw InputError("view", "expected raw or keyed, got \"" + view + "\"");
    const int width = static_cast<int>(IntParam(req, "width", 640, 16, 4096));
    const auto image = station()->Preview(
        req.matches[1], view == "keyed" ? PreviewView::kKeyed : PreviewView::kRaw, width);
    if (!image) {
      ReplyError(res, 503,
                 "camera \"" + std::string(req.matches[1]) + "\" has delivered no frame yet");
      return;
    }
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Frame-Sequence", std::to_string(image->sequence));
    res.set_header("X-Frame-Timestamp-Ns", std::to_string(image->timestamp_ns));
    res.set_header("X-Image-Width", std::to_string(image->width));
    res.set_header("X-Image-Height", std::to_string(image->height));
    res.set_content(reinterpret_cast<const char*>(image->jpeg.data()), image->jpeg.size(),
                    "image/jpeg");
  }

  void Sprites(const Request& req, Response& res) {
    const int width = static_cast<int>(IntParam(req, "width", 640, 16, 4096));
    const auto json = station()->SpritesView(req.matches[1], width);
    if (!json) {
      ReplyError(res, 503,
                 "camera \"" + std::string(req.matches[1]) + "\" has delivered no frame yet");
      return;
    }
    res.set_header("Cache-Control", "no-store");
    res.set_content(*json, "application/json");
  }

  void ReplayStart(const Request& req, Response& res) {
    const api::ReplayStartRequest r =
        api::ParseReplayStart(ObjectBody(req, api::kReplayStartFields));
    host->StartReplay(r.path, r.paced, r.loop);
    Reply(res, 200, host->ModeJson());
  }

  ConsoleBank Bank() const { return ConsoleBank(station()->bank_path()); }

  // Tag or untag: the same body either way.
  nlohmann::json Tag(const Request& req, bool remove) const {
    const int64_t n = Bank().Tag(ObjectBody(req, api::kTagFields), remove);
    return {{remove ? "untagged" : "tagged", n}};
  }

  void MakeRoutes() {
    const auto json = [](auto f) {
      return [f](const Request& req, Response& res) { Reply(res, 200, f(req)); };
    };
    routes = {
        {"GET", "/api", "GET /api: this list",
         [this](const Request&, Response& res) {
           nlohmann::json list = nlohmann::json::array();
           for (const Route& r : routes) list.push_back(r.listed);
           Reply(res, 200, {{"service", "spritestation"}, {"console", "/"}, {"endpoints", list}});
         }},
        {"GET", "/api/status", "GET /api/status",
         json([this](const Request&) { return StatusJson(); })},
        {"GET", "/metrics", "GET /metrics (Prometheus)",
         [this](const Request&, Response& res) {
           res.set_content(StatusToPrometheus(Status()), "text/plain; version=0.0.4");
         }},
        {"GET", "/api/events", "GET /api/events (Server-Sent Events)",
         [this](const Request& req, Response& res) { Events(req, res); }},
        {"GET", R"(/api/cameras/([^/]+)/preview\.jpg)",
         "GET /api/cameras/NAME/preview.jpg?view=raw|keyed&width=W",
         [this](const Request& req, Response& res) { Preview(req, res); }},
        {"GET", R"(/api/cameras/([^/]+)/sprites\.json)",
         "GET /api/cameras/NAME/sprites.json?width=W",
         [this](const Request& req, Response& res) { Sprites(req, res); }},
        {"POST", "/api/session/start", "POST /api/session/start {\"name\": S}",
         json([this](const Request& req) {
           std::string name = NameFromBody(req, false);
           return SessionToJson(station()->StartSession(name.empty() ? "session" : name));
         })},
        {"POST", "/api/session/stop", "POST /api/session/stop", json([this](const Request& req) {
           ObjectBody(req, {});
           return SessionToJson(station()->StopSession());
         })},
        {"POST", "/api/session/rename", "POST /api/session/rename {\"name\": S}",
         json([this](const Request& req) {
           return SessionToJson(station()->RenameSession(NameFromBody(req, true)));
         })},
        {"GET", "/api/replay/sessions", "GET /api/replay/sessions", json([this](const Request&) {
           return RecordedSessionsToJson(host->replay_roots(),
                                         FindRecordedSessions(host->replay_roots()));
         })},
        {"POST", "/api/replay/start",
         "POST /api/replay/start {\"path\": P, \"paced\": true, \"loop\": false}",
         [this](const Request& req, Response& res) { ReplayStart(req, res); }},
        {"POST", "/api/replay/stop", "POST /api/replay/stop", json([this](const Request& req) {
           ObjectBody(req, {});
           host->StopReplay();
           return host->ModeJson();
         })},
        {"GET", "/api/bank/sessions", "GET /api/bank/sessions",
         json([this](const Request&) { return Bank().Sessions(); })},
        {"GET", R"(/api/bank/sessions/([^/]+)/clips)", "GET /api/bank/sessions/ID/clips",
         json([this](const Request& req) { return Bank().Clips(PathId(req, "session")); })},
        {"GET", R"(/api/bank/clips/([^/]+)/sprites)", "GET /api/bank/clips/ID/sprites",
         json([this](const Request& req) { return Bank().ClipSprites(PathId(req, "clip")); })},
        {"GET", R"(/api/bank/sprites/([^/]+)/billboard\.png)",
         "GET /api/bank/sprites/ID/billboard.png?height=H",
         [this](const Request& req, Response& res) {
           const auto png = Bank().BillboardPng(
               PathId(req, "sprite"), static_cast<int>(IntParam(req, "height", 0, 0, 4096)));
           res.set_header("Cache-Control",
                          "private, max-age=3600");  // a stored billboard never changes
           res.set_content(reinterpret_cast<const char*>(png.data()), png.size(), "image/png");
         }},
        {"GET", R"(/api/bank/sprites/([^/]+))", "GET /api/bank/sprites/ID",
         json([this](const Request& req) { return Bank().Sprite(PathId(req, "sprite")); })},
        {"POST", "/api/bank/tag",
         "POST /api/bank/tag {\"tag\", \"sprites\" | \"clip\", \"first_frame\", \"last_frame\"}",
         json([this](const Request& req) { return Tag(req, false); })},
        {"POST", "/api/bank/untag", "POST /api/bank/untag (as tag)",
         json([this](const Request& req) { return Tag(req, true); })},
        {"GET", "/api/bank/export.csv", "GET /api/bank/export.csv?clip=ID|tag=T",
         [this](const Request& req, Response& res) {
           std::optional<int64_t> clip;
           if (req.has_param("clip")) clip = IntParam(req, "clip", 0, 1, INT64_MAX);
           const std::string tag = req.has_param("tag") ? req.get_param_value("tag") : "";
           if (!clip && tag.empty()) throw InputError("clip", "give ?clip=ID or ?tag=T");
           res.set_header("Content-Disposition",
                          "attachment; filename=\"" +
                              (clip ? "clip-" + std::to_string(*clip) : "tag-" + tag) + ".csv\"");
           res.set_content(Bank().ExportCsv(clip, tag), "text/csv; charset=utf-8");
         }},
    };
  }

  void Routes() {
    MakeParts();
    MakeRoutes();
    for (const auto& part : parts) {
      for (Route& r : part->Routes()) routes.push_back(std::move(r));
    }
    server.new_task_queue = [n = options.http_threads] { return new NiceThreadPool(n); };
    server.set_keep_alive_max_count(1000);
    server.set_read_timeout(10, 0);
    server.set_write_timeout(5,
                             0);  // a stalled event stream is dropped after 5 s of blocked writes
    server.set_pre_routing_handler(
        [this](const Request& req, Response& res) { return Admit(req, res); });
    for (const Route& r : routes) {
      route_patterns.emplace_back(r.pattern);
      auto handler = [h = r.handler](const Request& req, Response& res) {
        // A body must be JSON: a form or text/plain post from another site's page is refused
        // before anything acts (such a post needs no CORS preflight; a JSON one does).
        if (req.method == "POST" && !req.body.empty()) {
          const std::string type = req.get_header_value("Content-Type");
          if (type.rfind("application/json", 0) != 0) {
            ReplyError(res, 415,
                       "Content-Type: a request body must be JSON (application/json), got \"" +
                           type + "\"");
            return;
          }
        }
        Guard(res, [&] { h(req, res); });
      };
      if (std::string(r.method) == "GET") {
        server.Get(r.pattern, handler);
      } else {
        server.Post(r.pattern, handler);
      }
    }
    // The console's pages: everything else that GET asks for.
    server.Get(R"(/(|[A-Za-z0-9_\-./]+))", [this](const Request& req, Response& res) {
      if (req.path.rfind("/api/", 0) == 0 || !ServeWebFile(req.path, res)) NoRoute(req, res);
    });
    server.set_error_handler([this](const Request& req, Response& res) {
      if (!res.body.empty()) return;
      // A request the HTTP server could not read whole (cpp-httplib's bare 400): the limit it
      // broke.
      if (const auto fault = HttpServer::CurrentFault(); fault != HttpServer::RequestFault::kNone) {
        const auto [status, message] = HttpServer::FaultAnswer(fault, server.limits());
        ReplyError(res, status, message);
      } else if (res.status == 404 || res.status == 400) {
        NoRoute(req, res);
      } else if (res.status == 413) {
        ReplyError(
            res, 413,
            "body: larger than " + std::to_string(server.limits().max_body_bytes) + " bytes");
      } else if (res.status == 414) {
        ReplyError(res, 414,
                   "request line: longer than " +
                       std::to_string(server.limits().max_request_line_bytes) + " bytes");
      } else if (res.status >= 400) {
        ReplyError(res, res.status, "malformed request: " + req.method + " " + req.path);
      }
    });
  }

  // No route takes the request: 405 with the methods its path does take (cpp-httplib answers
  // 404 for those, or 400 for a method it does not know), else 404 (400: unknown method).
  void NoRoute(const Request& req, Response& res) const {
    const bool known_method = req.method == "GET" || req.method == "HEAD" || req.method == "POST" ||
                              req.method == "PUT" || req.method == "DELETE" ||
                              req.method == "PATCH" || req.method == "OPTIONS";
    const std::string allowed = MethodsOf(req.path);
    if (!allowed.empty()) {
      res.set_header("Allow", allowed);
      ReplyError(res, 405, "method: " + req.method + " " + req.path + " takes " + allowed);
    } else if (known_method) {
      ReplyError(res, 404,
                 "no such endpoint or page: " + req.method + " " + req.path +
                     " (GET /api lists the endpoints)");
    } else {
      ReplyError(res, 400, "malformed request: " + req.method + " " + req.path);
    }
  }

  // The methods that routes take at `path`, "GET, HEAD" style; "" when none matches it.
  std::string MethodsOf(const std::string& path) const {
    bool get = false, post = false;
    for (size_t i = 0; i < routes.size(); ++i) {
      if (!std::regex_match(path, route_patterns[i])) continue;
      (routes[i].method == "GET" ? get : post) = true;
    }
    if (!get && !post && path.rfind("/api/", 0) != 0 && options.embedded) {
      const std::optional<std::string> page = PagePath(path);
      get = page && options.embedded(*page);
    }
    std::string allowed = get ? "GET, HEAD" : "";
    if (post) allowed += allowed.empty() ? "POST" : ", POST";
    return allowed;
  }

  std::string Url() const {
    const bool v6 = options.config.address.find(':') != std::string::npos;
    return "http://" + (v6 ? "[" + options.config.address + "]" : options.config.address) + ":" +
           std::to_string(port);
  }
};

bool ControlServerOptions::IsValid(std::string* why) const {
  OptionProblems check(why);
  check.Within(config.port, Between(0, 65535), "config.port", "a port number 0..65535");
  check.Within(max_event_streams, AtLeast(0), "max_event_streams", "a number >= 0");
  check.Within(http_threads, Between(1, 4096), "http_threads", "1..4096 threads");
  return check.ok();
}

ControlServer::ControlServer(StationHost& host, ControlServerOptions options)
    : impl_(std::make_unique<Impl>()) {
  if (std::string why; !options.IsValid(&why)) throw InputError("control server options", why);
  impl_->host = &host;
  impl_->options = std::move(options);
  // Fewer connections in all than threads, so that a thread is free to refuse the next at once
  // (a connection waits for a thread before anything is read of it).
  HttpLimits limits;
  const int threads = impl_->options.http_threads;
  limits.max_connections_total =
      std::min(limits.max_connections_total, std::max(1, threads - std::max(1, threads / 8)));
  impl_->server.set_limits(limits);
  impl_->events = std::make_unique<ConsoleEvents>([s = impl_.get()] { return s->StatusJson(); });
  impl_->Routes();
}

ControlServer::~ControlServer() { Stop(); }

int ControlServer::Start() {
  Impl& s = *impl_;
  const std::string host =
      s.options.config.address == "localhost" ? "127.0.0.1" : s.options.config.address;
  s.port = s.server.Bind(host, s.options.config.port);
  if (s.port <= 0) {
    throw WorkError(
        "control " + s.options.config.address + ":" + std::to_string(s.options.config.port),
        "cannot listen there (address not on this machine, or the port is taken)");
  }
  s.events->Start();
  s.status_listener = s.host->AddStatusListener([&s] { s.events->Changed(); });
  s.thread = std::thread([&s] { s.server.listen_after_bind(); });
  Log("station.control")->info("control API and console on {}", s.Url());
  return s.port;
}

void ControlServer::Stop() {
  Impl& s = *impl_;
  for (const auto& part : s.parts) part->Stop();
  if (s.status_listener != 0) s.host->RemoveStatusListener(s.status_listener);
  s.status_listener = 0;
  s.events->Stop();  // event streams end, so the server's threads can
  if (s.thread.joinable()) {
    s.server.stop();
    s.thread.join();
  }
}

std::string ControlServer::url() const { return impl_->Url(); }

}  // namespace ss
