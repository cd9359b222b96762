#pragma once
// An engine's name as a Summary holds it: its own copy (a Summary outlives its engine, and a
// plugin's engine may name itself from a string it owns), without allocation (engines fill a
// Summary on every solve, hot loops included). Registry names are 1 to 64 characters
// (registry_name.hpp); a longer name() is kept to its first 64 bytes, cut at a UTF-8 boundary.
#include <array>
#include <cstddef>
#include <ostream>
#include <string>
#include <string_view>

namespace nlobs {

class EngineName {
 public:
  static constexpr std::size_t kCapacity = 64;

  EngineName() = default;
  EngineName(std::string_view name) { assign(name); }  // NOLINT: summary.engine = name()
  EngineName& operator=(std::string_view name) {
    assign(name);
    return *this;
  }

  std::string_view view() const { return {text_.data(), size_}; }
  operator std::string_view() const { return view(); }  // NOLINT: reads as the name it holds
  std::string str() const { return std::string(view()); }
  const char* c_str() const { return text_.data(); }  // NUL-terminated
  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }

  friend bool operator==(const EngineName& a, std::string_view b) { return a.view() == b; }
  friend bool operator==(const EngineName& a, const EngineName& b) { return a.view() == b.view(); }
  friend std::ostream& operator<<(std::ostream& out, const EngineName& name) {
    return out << name.view();
  }

 private:
  void assign(std::string_view name) {
    std::size_t n = name.size() < kCapacity ? name.size() : kCapacity;
    // Not inside a UTF-8 sequence: back off continuation bytes (10xxxxxx) and the lead byte.
    if (n < name.size()) {
      while (n > 0 && (static_cast<unsigned char>(name[n]) & 0xC0U) == 0x80U) --n;
    }
    for (std::size_t i = 0; i < n; ++i) text_[i] = name[i];
    text_[n] = '\0';
    size_ = n;
  }

  std::array<char, kCapacity + 1> text_{};
  std::size_t size_ = 0;
};

}  // namespace nlobs
