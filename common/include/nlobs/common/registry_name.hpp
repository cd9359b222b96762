#pragma once
// The one name rule of every registry: models, observer types, engines, problem sets (and a
// problem set's problems). A name is 1 to 64 characters, each an ASCII letter, digit or one of
// _ . + -, so that it can be typed on a command line, in an engine spec ("name:key=value",
// hence no ':' ',' '=') and in SET/NAME (no '/'), and printed in a message or `nlobs list`
// without escaping (no control character, quote or space). 64 is far above every built-in name
// (the longest is under 30) and short enough for a table column.
//
// registry_name_problem(name): why `name` is not one ("" when it is), naming the first bad
// character or the length. registry_name_refusal(kind, name, source): the message every
// registry and the plugin loader refuse with, echoing the name through printable(…, 60).
#include <cstddef>
#include <string>
#include <string_view>

#include "nlobs/common/printable.hpp"

namespace nlobs {

inline constexpr std::size_t kRegistryNameMaxLength = 64;

inline constexpr std::string_view kRegistryNameRule =
    "a name is 1 to 64 characters: ASCII letters, digits and _ . + -";

inline bool is_registry_name_character(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '.' || c == '+' || c == '-';
}

inline std::string registry_name_problem(std::string_view name) {
  if (name.empty()) return "is empty";
  if (name.size() > kRegistryNameMaxLength) {
    return "has " + std::to_string(name.size()) + " bytes, more than " +
           std::to_string(kRegistryNameMaxLength);
  }
  for (std::size_t i = 0; i < name.size(); ++i) {
    if (!is_registry_name_character(name[i])) {
      // printable() shows a control character as \xHH; so is a byte of a UTF-8 character, which
      // on its own is not valid UTF-8.
      const std::string shown = printable(name.substr(i, 1), 8);
      return "has '" + shown + "' at byte " + std::to_string(i + 1);
    }
  }
  return {};
}

inline bool is_registry_name(std::string_view name) {
  return registry_name_problem(name).empty();
}

// "engine name 'a\nb' from /p/libx.so has '\n' at byte 2 (a name is 1 to 64 characters: …)".
inline std::string registry_name_refusal(std::string_view kind, std::string_view name,
                                         std::string_view source) {
  return std::string(kind) + " name '" + printable(name, 60) + "' from " + printable(source) + " " +
         registry_name_problem(name) + " (" + std::string(kRegistryNameRule) + ")";
}

}  // namespace nlobs
