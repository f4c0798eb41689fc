#pragma once
// The skeleton sequence file (format "spritestation.skeleton_sequence", version 1;
// docs/skeletons.md): the skeleton definition (or a built-in name) and per frame a
// position and confidence per joint, null for a missing joint.
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "animate/skeleton/skeleton.h"

namespace ss {

// Parses a sequence document; `context` (the file path) names the source in errors.
// Throws InputError naming the frame and joint for a missing or unknown joint, a wrong
// joint count or a malformed value.
SkeletonSequence SkeletonSequenceFromJson(const nlohmann::json& json, const std::string& context);
nlohmann::json SkeletonSequenceToJson(const SkeletonSequence& sequence);

SkeletonSequence ReadSkeletonSequence(const std::string& path);
void WriteSkeletonSequence(const SkeletonSequence& sequence, const std::string& path);

// One frame's joints: an object keyed by joint name (every joint listed, null when
// missing) or an array of exactly joint_count() entries. `where` prefixes errors.
SkeletonFrame SkeletonFrameFromJson(const nlohmann::json& joints, const SkeletonDef& def,
                                    const std::string& where);

}  // namespace ss
