#pragma once
// Kinds of error that a caller answers differently: bad input (HTTP 404, 409; both stay
// InputErrors, exit code 2, for every command-line caller), and failures worth retrying.
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

// A resource was held by someone else for longer than we wait (a database's write lock):
// nothing is wrong with the work, which may be tried again.
class BusyError : public WorkError {
 public:
  using WorkError::WorkError;
};

}  // namespace ss
