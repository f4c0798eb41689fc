#pragma once
// Move-only owners for GLib handles used by the Aravis backend: a GObject
// reference (g_object_unref on destruction) and a GError turned into text.
#include <memory>
#include <string>

#include <glib-object.h>

namespace ss {

struct GObjectUnref {
  void operator()(void* object) const {
    if (object != nullptr) g_object_unref(object);
  }
};

// Owns one reference to a GObject of type T.
template <typename T>
using GObjectPtr = std::unique_ptr<T, GObjectUnref>;

// Owns a GError set by a GLib call; empty when the call succeeded.
class GErrorHolder {
 public:
  GErrorHolder() = default;
  ~GErrorHolder() { Clear(); }
  GErrorHolder(const GErrorHolder&) = delete;
  GErrorHolder& operator=(const GErrorHolder&) = delete;

  GError** out() {
    Clear();
    return &error_;
  }
  explicit operator bool() const { return error_ != nullptr; }
  std::string message() const { return error_ != nullptr ? error_->message : ""; }
  void Clear() {
    if (error_ != nullptr) g_error_free(error_);
    error_ = nullptr;
  }

 private:
  GError* error_ = nullptr;
};

}  // namespace ss
