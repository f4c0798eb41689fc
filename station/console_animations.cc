#include "station/console_animations.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>

#include "capture/camera_source.h"
#include "config/station_config.h"
#include "core/bank.h"
#include "core/error.h"
#include "core/error_kinds.h"
#include "core/log.h"
#include "core/yaml_reader.h"
#include "station/station_host.h"

// After every header that may include Eigen (api_part.h says why).
#include <httplib.h>

namespace ss {

namespace fs = std::filesystem;
using api::Json;
using api::Reply;
using api::Route;

namespace {

bool IsSqliteBank(const std::string& bank) { return bank.rfind("postgresql://", 0) != 0; }

// The camera's model file when it exists (capture/camera_source.h); "" when it has none or its
// session cannot be read, as for a live camera without one.
std::string ModelOf(const CameraConfig& camera) {
  std::string model;
  try {
    model = ModelFileForCamera(camera);
  } catch (const InputError&) {
    return "";
  }
  std::error_code ec;
  return !model.empty() && fs::exists(model, ec) ? model : "";
}

// The file `path` as the response, with its type by extension.
void SendFile(httplib::Response& res, const std::string& path) {
  const std::string ext = fs::path(path).extension().string();
  const char* type = ext == ".jpg"    ? "image/jpeg"
                     : ext == ".png"  ? "image/png"
                     : ext == ".mp4"  ? "video/mp4"
                     : ext == ".json" ? "application/json"
                                      : "text/yaml; charset=utf-8";
  std::ifstream in(path, std::ios::binary);
  if (!in) throw NotFoundError("file", "cannot read " + fs::path(path).filename().string());
  std::string body((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  res.set_content(body, type);
}

// YAML as JSON, for the page (which reads JSON only): a plain scalar that reads whole as a
// number, true / false or null is one; everything else, and every quoted scalar, is text.
nlohmann::json JsonOfYaml(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Sequence: {
      nlohmann::json list = nlohmann::json::array();
      for (const YAML::Node& item : node) list.push_back(JsonOfYaml(item));
      return list;
    }
    case YAML::NodeType::Map: {
      nlohmann::json map = nlohmann::json::object();
      for (const auto& item : node) map[item.first.Scalar()] = JsonOfYaml(item.second);
      return map;
    }
    case YAML::NodeType::Scalar: {
      const std::string& text = node.Scalar();
      if (node.Tag() == "!") return text;  // quoted
      if (text == "true" || text == "false") return text == "true";
      if (text == "null" || text == "~") return nullptr;
      char* end = nullptr;
      const double number = std::strtod(text.c_str(), &end);
      if (!text.empty() && end == text.c_str() + text.size() && std::isfinite(number)) {
        const bool whole = text.find_first_of(".eE") == std::string::npos;
        return whole && std::abs(number) < 9e15 ? nlohmann::json(static_cast<int64_t>(number))
                                                : nlohmann::json(number);
      }
      return text;
    }
    default:
      return nullptr;
  }
}

}  // namespace

AnimationJobsOptions StationAnimationOptions(const StationConfig& config,
                                             const std::string& config_path,
                                             const std::vector<std::string>& replay_roots) {
  AnimationJobsOptions options;
  const std::string& bank = config.storage.bank;
  const fs::path beside = IsSqliteBank(bank) ? fs::path(bank).parent_path()
                                             : fs::path(config.storage.recording_dir).parent_path();
  options.folder = (beside / "animations").string();
  options.base_dir = beside.string();
  std::set<std::string> roots = {beside.string()};
  if (!config.storage.recording_dir.empty()) roots.insert(config.storage.recording_dir);
  if (!config_path.empty()) roots.insert(fs::absolute(config_path).parent_path().string());
  for (const CameraConfig& camera : config.cameras) {
    if (const std::string model = ModelOf(camera); !model.empty()) {
      roots.insert(fs::path(model).parent_path().string());
    }
  }
  for (const std::string& root : replay_roots) roots.insert(fs::absolute(root).string());
  options.roots.assign(roots.begin(), roots.end());
  return options;
}

ConsoleAnimations::ConsoleAnimations(api::Context context) : context_(std::move(context)) {
  if (context_.host == nullptr) return;
  AnimationJobsOptions options = StationAnimationOptions(
      context_.host->live_config(), context_.config_path, context_.host->replay_roots());
  options.changed = context_.status_changed;
  jobs_ = std::make_unique<AnimationJobs>(std::move(options));
}

ConsoleAnimations::~ConsoleAnimations() { Stop(); }

void ConsoleAnimations::Stop() {
  if (jobs_) jobs_->Stop();
}

AnimationJobs& ConsoleAnimations::Jobs() const {
  if (!jobs_) throw WorkError("animations", "this daemon has no station config");
  return *jobs_;
}

void ConsoleAnimations::AddStatus(nlohmann::json& status) const {
  status["animation"] = jobs_ ? jobs_->Brief() : nlohmann::json(nullptr);
}

nlohmann::json ConsoleAnimations::Inputs() const {
  const AnimationJobs& jobs = Jobs();
  const StationConfig config = context_.host->live_config();
  nlohmann::json cameras = nlohmann::json::array();
  std::set<std::string> image_folders = {jobs.options().base_dir};
  for (const CameraConfig& camera : config.cameras) {
    const std::string model = ModelOf(camera);
    if (model.empty()) continue;
    cameras.push_back({{"name", camera.name}, {"model", model}});
    image_folders.insert(fs::path(model).parent_path().string());
  }
  // Virtual cameras beside the bank (the reference sets' virtual.cameramodel), by their stem.
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(jobs.options().base_dir, ec)) {
    const std::string path = entry.path().string();
    if (entry.path().extension() != ".cameramodel" ||
        std::any_of(cameras.begin(), cameras.end(),
                    [&](const nlohmann::json& c) { return c["model"] == path; })) {
      continue;
    }
    cameras.push_back({{"name", entry.path().stem().string()}, {"model", path}});
  }
  std::set<std::string> backgrounds;
  for (const std::string& folder : image_folders) {
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
      const std::string ext = entry.path().extension().string();
      if (entry.is_regular_file(ec) && (ext == ".png" || ext == ".jpg" || ext == ".jpeg")) {
        backgrounds.insert(entry.path().string());
      }
    }
  }
  nlohmann::json enclosure = nlohmann::json::array();
  for (const Eigen::Vector2d& v : config.enclosure.floor.vertices()) {
    enclosure.push_back({v.x(), v.y()});
  }
  std::set<std::string> tags;
  nlohmann::json bank = nullptr;
  if (IsSqliteBank(config.storage.bank)) {
    bank = config.storage.bank;
    try {
      for (const auto& [clip, counts] : Bank(config.storage.bank).CountClipTags()) {
        for (const auto& [tag, n] : counts) tags.insert(tag);
      }
    } catch (const InputError& e) {  // no bank yet: nothing to animate, said by the spec check
      Log("station.animations")->warn("{}", e.what());
    }
  }
  return {{"bank", bank},
          {"cameras", std::move(cameras)},
          {"backgrounds", backgrounds},
          {"enclosure", std::move(enclosure)},
          {"tags", tags},
          {"max_time_budget_s", jobs.options().max_time_budget_s},
          {"frame_rate", 30}};
}

std::vector<Route> ConsoleAnimations::Routes() {
  const std::string id = R"((\d{1,12}))";
  return {
      {"GET", "/api/animations/inputs", "GET /api/animations/inputs",
       Json([this](const httplib::Request&) { return Inputs(); })},
      {"GET", "/api/animations", "GET /api/animations",
       Json([this](const httplib::Request&) { return Jobs().List(); })},
      {"POST", "/api/animations", "POST /api/animations {\"spec\": YAML}",
       [this](const httplib::Request& req, httplib::Response& res) {
         const nlohmann::json body = api::ObjectBody(req, {"spec"});
         if (!body.contains("spec") || !body["spec"].is_string()) {
           throw InputError("spec", "required: the animation spec's YAML text");
         }
         const int64_t job = Jobs().Submit(body["spec"].get<std::string>());
         Reply(res, 202, {{"id", job}, {"state", "queued"}});
       }},
      {"POST", "/api/animations/spec.json", "POST /api/animations/spec.json {\"spec\": YAML}",
       Json([](const httplib::Request& req) {
         const nlohmann::json body = api::ObjectBody(req, {"spec"});
         if (!body.contains("spec") || !body["spec"].is_string()) {
           throw InputError("spec", "required: the animation spec's YAML text");
         }
         return nlohmann::json{{"spec", JsonOfYaml(yaml_text::LoadOneDocument(
                                            body["spec"].get<std::string>(), "spec"))}};
       })},
      {"GET", "/api/animations/" + id, "GET /api/animations/ID",
       Json([this](const httplib::Request& req) {
         return Jobs().Job(api::PathId(req, "animation"));
       })},
      {"POST", "/api/animations/" + id + "/cancel", "POST /api/animations/ID/cancel",
       Json([this](const httplib::Request& req) {
         return Jobs().Cancel(api::PathId(req, "animation"));
       })},
      {"GET", "/api/animations/" + id + R"(/files/([a-z]+\.[a-z0-9]+))",
       "GET /api/animations/ID/files/NAME",
       [this](const httplib::Request& req, httplib::Response& res) {
         SendFile(res, Jobs().File(api::PathId(req, "animation"), api::PathText(req, 2)));
       }},
      {"GET", "/api/animations/" + id + R"(/frames/(\d{1,6})\.jpg)",
       "GET /api/animations/ID/frames/T.jpg",
       [this](const httplib::Request& req, httplib::Response& res) {
         const int step = static_cast<int>(api::ParseInt(api::PathText(req, 2), "step", 0, 999999));
         SendFile(res, Jobs().Frame(api::PathId(req, "animation"), step));
         res.set_header("Cache-Control", "private, max-age=3600");  // a saved frame never changes
       }},
  };
}

}  // namespace ss
