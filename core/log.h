#pragma once
// Logging by component ("capture.replay", "pipeline.key", ...), levels set at run time.
#include <memory>
#include <string>

#include <spdlog/spdlog.h>

namespace ss {

// The logger of one component; created on first use, shared afterwards.
std::shared_ptr<spdlog::logger> Log(const std::string& component);

// Sets the level of every logger, present and future ("trace".."off").
void SetLogLevel(const std::string& level);

}  // namespace ss
