#pragma once
// Closed sets are enums in the program and text only in files and the API (Ceres's
// StringToLinearSolverType): each enum has one table of its values' texts, read by the
// YAML reader (core/yaml_reader.h) and written by ToText.
#include <cstddef>

namespace ss {

template <typename E>
struct EnumText {
  E value;
  const char* text;
};

// The text of `value` in `texts`; "unknown" when it has none.
template <typename E, size_t N>
const char* TextOf(E value, const EnumText<E> (&texts)[N]) {
  for (const EnumText<E>& t : texts) {
    if (t.value == value) return t.text;
  }
  return "unknown";
}

}  // namespace ss
