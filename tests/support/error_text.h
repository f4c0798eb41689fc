#pragma once
// What an InputError says, for tests that check a refusal names the file or field.
#include <functional>
#include <string>

#include "core/error.h"

namespace ss::testing {

// The message of the InputError `f` throws; "" when it throws none.
inline std::string InputErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace ss::testing
