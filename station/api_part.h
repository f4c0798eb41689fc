#pragma once
// A part of the control API in a file of its own (the calibration wizard, the
// labelling page, ...): its routes, and what it adds to the status every
// console receives over `/api/events`. The control server (control_server.cc)
// owns the parts, puts their routes in its one table (so `GET /api` lists
// them and every request passes the same checks: Host, Origin, token, JSON
// bodies, 1 MiB limit) and maps a handler's exception to a status by its kind
// (core/error_kinds.h): NotFoundError 404, ConflictError 409, InputError 400,
// anything else 500.
//
// httplib is only forward-declared here: a part's .cc includes <httplib.h>
// itself, after any Eigen header (resolv.h's `_res` macro breaks Eigen).
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "station/request_bodies.h"  // Dump, ObjectBody of a body's text, and each route's request

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace ss {

class Station;
class StationHost;

namespace api {

using Handler = std::function<void(const httplib::Request&, httplib::Response&)>;

struct Route {
  std::string method;   // GET | POST
  std::string pattern;  // httplib regex; groups are in req.matches
  std::string listed;   // as GET /api lists it: "POST /api/thing {\"field\": ...}"
  Handler handler;
};

void Reply(httplib::Response& res, int status, const nlohmann::json& body);
// {"error": message}; a message over 1 KiB (one that quotes what was sent) is cut to 960 bytes.
void ReplyError(httplib::Response& res, int status, const std::string& message);
// A handler that answers 200 with what `f(req)` returns.
Handler Json(std::function<nlohmann::json(const httplib::Request&)> f);

// The request's body as a JSON object: ObjectBody(req.body, fields) (request_bodies.h).
nlohmann::json ObjectBody(const httplib::Request& req, std::initializer_list<const char*> fields);
// `text` as a whole integer within [lo, hi]; InputError naming `name` otherwise.
int64_t ParseInt(const std::string& text, const char* name, int64_t lo, int64_t hi);
// An integer query parameter within [lo, hi], or `fallback` when absent.
int64_t IntParam(const httplib::Request& req, const char* name, int64_t fallback, int64_t lo,
                 int64_t hi);
// The path's first group as an id >= 1.
int64_t PathId(const httplib::Request& req, const char* what);
// The path's group `i` as text.
std::string PathText(const httplib::Request& req, size_t i = 1);

// What a part may use of the daemon.
struct Context {
  StationHost* host = nullptr;
  // The running station; WorkError "station: not running" when there is none.
  std::function<std::shared_ptr<Station>()> station;
  std::string config_path;  // the daemon's --config file ("" when it has none: tests)
  // Tells the console's events that the part's status changed (a job's phase, a wizard's
  // state): they send it at once instead of at the next second. Any thread; no lock is taken
  // but the events' own. Never empty (a no-op in tests without events).
  std::function<void()> status_changed = [] {};
};

class Part {
 public:
  virtual ~Part() = default;
  virtual std::vector<Route> Routes() = 0;
  // Adds this part's members to the status JSON (up to 4 times a second for the events stream,
  // and on every GET /api/status): keep it cheap and never block on long work. A change a
  // viewer acts on is told with Context::status_changed.
  virtual void AddStatus(nlohmann::json& /*status*/) const {}
  // The server stops: end background work (called before the parts are destroyed).
  virtual void Stop() {}
};

}  // namespace api
}  // namespace ss
