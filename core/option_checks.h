#pragma once
// IsValid(std::string* why) of a component's options struct: every value out of its range, one
// line "FIELD: reason" each in `why` (FIELD as the struct names it; the station config names
// it by its key: config/config_validate.cc). A number's bounds are a NumberRule, the same words
// the config's key bindings use (core/options_binder.h): one rule vocabulary.
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace ss {

// The bounds of a number: checked on an options field (OptionProblems::Within) and on a config
// key's value, whether read from a file or set in code (OptionsBinder::CheckRules), and written
// into the key's type in the docs ("number > 0", "integer 0..65535"). A value out of them is
// reported as "expected EXPECTED, got V" with the caller's `expected` words, which therefore say
// the bounds ("at least 1 frame"). NaN and infinities hold no rule.
struct NumberRule {
  double min = -1e300, max = 1e300;
  bool min_open = false;  // min itself is out (> rather than >=)
  bool max_open = false;  // max itself is out (< rather than <=)
  bool Holds(double v) const {
    return std::isfinite(v) && (min_open ? v > min : v >= min) && (max_open ? v < max : v <= max);
  }
  std::string Text() const;  // "> 0", ">= 1", "0..255", ">= 0, < 1" (core/options_binder.cc)
};
inline NumberRule Positive() { return {0, 1e300, true}; }
inline NumberRule AtLeast(double min) { return {min, 1e300, false}; }
inline NumberRule Between(double min, double max) { return {min, max, false}; }
// [min, max): a fraction that may be 0 but not 1.
inline NumberRule FromUpTo(double min, double max) { return {min, max, false, true}; }
// (min, max]: a factor that may be `max` but not 0.
inline NumberRule AboveUpTo(double min, double max) { return {min, max, true, false}; }
// (min, max): neither end.
inline NumberRule Inside(double min, double max) { return {min, max, true, true}; }

class OptionProblems {
 public:
  explicit OptionProblems(std::string* why) : why_(why) {
    if (why_) why_->clear();
  }
  // Adds "field: reason" unless `good`.
  void operator()(bool good, const std::string& field, const std::string& reason) {
    if (good) return;
    ok_ = false;
    if (why_) *why_ += (why_->empty() ? "" : "\n") + field + ": " + reason;
  }
  // The same with the reason written only when needed: for options checked on a hot path (each
  // call of ContactPoint), where building every reason would cost more than the check.
  template <class Reason>
  requires std::is_invocable_r_v<std::string, Reason>
  void operator()(bool good, const char* field, Reason&& reason) {
    if (good) return;
    (*this)(false, field, std::forward<Reason>(reason)());
  }
  // Adds "field: expected EXPECTED, got VALUE" unless `rule` holds `value`.
  void Within(double value, NumberRule rule, std::string_view field, std::string_view expected) {
    if (rule.Holds(value)) return;  // nothing built: IsValid may run on a hot path
    (*this)(false, std::string(field), "expected " + std::string(expected) + ", got " + Num(value));
  }
  // Another struct's problems (its IsValid's `why`), each field under `prefix` ("extract.").
  void Nested(bool good, const std::string& prefix, const std::string& why) {
    if (good) return;
    ok_ = false;
    if (!why_) return;
    std::istringstream lines(why);
    for (std::string line; std::getline(lines, line);)
      *why_ += (why_->empty() ? "" : "\n") + prefix + line;
  }
  bool ok() const { return ok_; }

  // The problems an IsValid wrote into `why`, back as fields and reasons, for a reader that names
  // each at its own key (the station config, the animation spec). A line without "field: " has
  // the field "".
  struct Problem {
    std::string field, reason;
  };
  static std::vector<Problem> Split(const std::string& why) {
    std::vector<Problem> problems;
    std::istringstream lines(why);
    for (std::string line; std::getline(lines, line);) {
      const size_t colon = line.find(": ");
      if (colon == std::string::npos) {
        problems.push_back({"", line});
      } else {
        problems.push_back({line.substr(0, colon), line.substr(colon + 2)});
      }
    }
    return problems;
  }

  // A number as the messages write it ("25", "0.5", "3000000000": a whole number in full).
  static std::string Num(double v) {
    if (std::isfinite(v) && v == std::floor(v) && std::abs(v) < 1e15)
      return std::to_string(static_cast<int64_t>(v));
    std::ostringstream s;
    s << v;
    return s.str();
  }

 private:
  std::string* why_;
  bool ok_ = true;
};

}  // namespace ss
