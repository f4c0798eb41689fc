#pragma once
// What an options struct's IsValid says (core/option_checks.h), for the options tests.
#include <string>

#include <gtest/gtest.h>

namespace ss::testing {

// The problems `options` has (its IsValid's `why`), "" when it is valid; IsValid's result must
// agree with `why` being empty.
template <typename Options>
std::string Problems(const Options& options) {
  std::string why = "stale";
  const bool ok = options.IsValid(&why);
  EXPECT_EQ(ok, why.empty()) << why;
  return why;
}

// True when `why` has a line starting "FIELD: ".
inline bool Names(const std::string& why, const std::string& field) {
  return why.rfind(field + ": ", 0) == 0 || why.find("\n" + field + ": ") != std::string::npos;
}

}  // namespace ss::testing
