#pragma once
// Closed sets are enums in the program and text only in files and the API (Ceres's
// StringToLinearSolverType): each enum has one table of its values' texts, read by the
// YAML reader (core/yaml_reader.h) and written by ToText.
#include <cstddef>
#include <string>
#include <string_view>

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

// The value whose text is `text`: false, and `out` untouched, when `texts` has none.
template <typename E, size_t N>
bool FromText(std::string_view text, const EnumText<E> (&texts)[N], E& out) {
  for (const EnumText<E>& t : texts) {
    if (text == t.text) {
      out = t.value;
      return true;
    }
  }
  return false;
}

// The texts for a message or a help line: "a, b or c".
template <typename E, size_t N>
std::string TextsOf(const EnumText<E> (&texts)[N]) {
  std::string out;
  for (size_t i = 0; i < N; ++i) {
    if (i > 0) out += i + 1 == N ? " or " : ", ";
    out += texts[i].text;
  }
  return out;
}

}  // namespace ss
