#pragma once
// Text that came from a user (a plugin's names, a path, an exception's message, a file's cell)
// made safe to echo: a message nlobs prints must not carry a terminal escape sequence, a line
// break that forges a second line, or ten thousand characters.
//
// printable(text, limit): control characters (C0, DEL, and the C1 range U+0080..U+009F, which
// some terminals take as escapes) and bytes that are not valid UTF-8 are written as \xNN; every
// other character (UTF-8 included) is kept. At most `limit` bytes of the text are shown, never
// half a character, and "..." marks a cut (docs/cli.md: user text in messages).
//
// current_exception_text(): inside a catch block, the printable message of the exception being
// handled: what() for a std::exception, "a non-standard exception" for anything else
// (`throw 42`), so that `catch (...)` can still say something.
#include <cstddef>
#include <exception>
#include <string>
#include <string_view>

namespace nlobs {

inline constexpr std::size_t kPrintableLimit = 200;

namespace detail {

// The length of the valid UTF-8 sequence at text[i] (2..4), 0 when there is none.
inline std::size_t utf8_sequence_length(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  std::size_t length = 0;
  unsigned char low = 0x80, high = 0xBF;  // the range of the second byte (RFC 3629, table 3-7)
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) low = 0xA0;   // no overlong forms
    if (lead == 0xED) high = 0x9F;  // no surrogates
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) low = 0x90;
    if (lead == 0xF4) high = 0x8F;  // nothing above U+10FFFF
  } else {
    return 0;
  }
  if (i + length > text.size()) return 0;
  if (byte(i + 1) < low || byte(i + 1) > high) return 0;
  for (std::size_t k = 2; k < length; ++k) {
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  }
  return length;
}

inline void append_hex_escape(std::string& out, unsigned char c) {
  constexpr char digits[] = "0123456789abcdef";
  out += "\\x";
  out += digits[c >> 4];
  out += digits[c & 0xF];
}

}  // namespace detail

inline std::string printable(std::string_view text, std::size_t limit = kPrintableLimit) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    const auto c = static_cast<unsigned char>(text[i]);
    std::size_t length = 1;
    bool escape = c < 0x20 || c == 0x7F;
    if (c >= 0x80) {
      length = detail::utf8_sequence_length(text, i);
      // C1 controls (U+0080..U+009F) are C2 80..C2 9F in UTF-8.
      const bool c1 = length == 2 && c == 0xC2 && static_cast<unsigned char>(text[i + 1]) < 0xA0;
      if (length == 0 || c1) {
        length = 1;
        escape = true;
      }
    }
    if (i + length > limit) break;
    if (escape) {
      detail::append_hex_escape(out, c);
    } else {
      out.append(text.substr(i, length));
    }
    i += length;
  }
  if (i < text.size()) out += "...";
  return out;
}

// Call only inside a catch block.
inline std::string current_exception_text(std::size_t limit = kPrintableLimit) {
  try {
    throw;
  } catch (const std::exception& e) {
    return printable(e.what(), limit);
  } catch (...) {
    return "a non-standard exception";
  }
}

}  // namespace nlobs
