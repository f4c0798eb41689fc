#pragma once
// Kinds of bad input that a caller answers differently (HTTP 404, 409); both
// stay InputErrors (exit code 2) for every command-line caller.
#include "core/error.h"

namespace ss {

// What the input names does not exist (a camera, a sprite, a session).
class NotFoundError : public InputError {
 public:
  using InputError::InputError;
};

// The request is valid but not in this state (a session already running, none running).
class ConflictError : public InputError {
 public:
  using InputError::InputError;
};

}  // namespace ss
