#include "station/api_part.h"

#include <algorithm>

#include <httplib.h>

#include "core/error.h"

namespace ss::api {

void Reply(httplib::Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_content(Dump(body, 2) + "\n", "application/json");
}

void ReplyError(httplib::Response& res, int status, const std::string& message) {
  // An error may quote what was sent (a path, a JSON parser's "last read" token): never more
  // than a short excerpt of it.
  constexpr size_t kMostBytes = 1024;
  if (message.size() <= kMostBytes) {
    Reply(res, status, {{"error", message}});
    return;
  }
  size_t cut = kMostBytes - 64;
  while (cut > 0 && (static_cast<unsigned char>(message[cut]) & 0xC0) == 0x80) --cut;
  Reply(res, status,
        {{"error", message.substr(0, cut) + "... (cut: " + std::to_string(message.size()) +
                       " bytes in all)"}});
}

Handler Json(std::function<nlohmann::json(const httplib::Request&)> f) {
  return [f = std::move(f)](const httplib::Request& req, httplib::Response& res) {
    Reply(res, 200, f(req));
  };
}

nlohmann::json ObjectBody(const httplib::Request& req, std::initializer_list<const char*> fields) {
  return ObjectBody(req.body, fields);
}

int64_t ParseInt(const std::string& text, const char* name, int64_t lo, int64_t hi) {
  size_t used = 0;
  int64_t v = 0;
  try {
    v = std::stoll(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || v < lo || v > hi) {
    throw InputError(name, "expected an integer from " + std::to_string(lo) + " to " +
                               std::to_string(hi) + ", got \"" + text + "\"");
  }
  return v;
}

int64_t IntParam(const httplib::Request& req, const char* name, int64_t fallback, int64_t lo,
                 int64_t hi) {
  return req.has_param(name) ? ParseInt(req.get_param_value(name), name, lo, hi) : fallback;
}

int64_t PathId(const httplib::Request& req, const char* what) {
  return ParseInt(req.matches[1], what, 1, INT64_MAX);
}

std::string PathText(const httplib::Request& req, size_t i) { return req.matches[i]; }

}  // namespace ss::api
