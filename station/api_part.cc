#include "station/api_part.h"

#include <algorithm>

#include <httplib.h>

#include "core/error.h"

namespace ss::api {

std::string Dump(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

void Reply(httplib::Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_content(Dump(body, 2) + "\n", "application/json");
}

void ReplyError(httplib::Response& res, int status, const std::string& message) {
  Reply(res, status, {{"error", message}});
}

Handler Json(std::function<nlohmann::json(const httplib::Request&)> f) {
  return [f = std::move(f)](const httplib::Request& req, httplib::Response& res) { Reply(res, 200, f(req)); };
}

nlohmann::json ObjectBody(const httplib::Request& req, std::initializer_list<const char*> fields) {
  if (req.body.empty()) return nlohmann::json::object();
  nlohmann::json body;
  try {
    body = nlohmann::json::parse(req.body);
  } catch (const nlohmann::json::exception& e) {
    throw InputError("body", std::string("not valid JSON: ") + e.what());
  }
  if (!body.is_object()) throw InputError("body", "expected a JSON object");
  for (const auto& [key, value] : body.items()) {
    if (std::none_of(fields.begin(), fields.end(), [&](const char* f) { return key == f; })) {
      std::string list;
      for (const char* f : fields) list += std::string(list.empty() ? "" : ", ") + "\"" + f + "\"";
      throw InputError(key, "unknown field (the request takes " + (list.empty() ? std::string("none") : list) + ")");
    }
  }
  return body;
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
    throw InputError(name, "expected an integer from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got \"" +
                               text + "\"");
  }
  return v;
}

int64_t IntParam(const httplib::Request& req, const char* name, int64_t fallback, int64_t lo, int64_t hi) {
  return req.has_param(name) ? ParseInt(req.get_param_value(name), name, lo, hi) : fallback;
}

int64_t PathId(const httplib::Request& req, const char* what) { return ParseInt(req.matches[1], what, 1, INT64_MAX); }

std::string PathText(const httplib::Request& req, size_t i) { return req.matches[i]; }

}  // namespace ss::api
