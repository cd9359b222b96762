#pragma once
// Engine spec strings: "name[:item[,item...]]", an item being "key=value" or a bare word
// (e.g. "steffensen", "anderson:m=3,damping=0.5", "newton:linesearch=1", "ceres:dogleg",
// "nlopt:LN_BOBYQA,xtol_rel=1e-6"). EngineSpecReader reads typed values and refuses anything
// the engine does not understand, listing what it does.
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "nlobs/solvers/status.hpp"

namespace nlobs {

struct EngineSpec {
  std::string text;                                         // as given
  std::string name;                                         // before ':'
  std::vector<std::string> words;                           // bare items, in order
  std::vector<std::pair<std::string, std::string>> values;  // key=value items, in order
};

// Throws InvalidInput for an empty name, an empty item or a duplicated key.
EngineSpec parse_engine_spec(std::string_view text);

struct EngineOptionInfo {
  std::string key;          // "m", "damping", ... ; for words: "<word>"
  std::string description;  // with the default
};

class EngineSpecReader {
 public:
  // `valid` lists the options of the engine for error messages.
  EngineSpecReader(const EngineSpec& spec, std::vector<EngineOptionInfo> valid);

  std::optional<double> number(const std::string& key);
  // An integer in [min, max]; otherwise InvalidInput naming the key, the value and the range.
  std::optional<int> integer(const std::string& key, int min, int max);
  std::optional<bool> boolean(const std::string& key);  // 0/1, true/false, on/off
  std::optional<std::string> text(const std::string& key);
  // The single bare word, if any, which must be one of `allowed` (empty: any).
  std::optional<std::string> word(const std::vector<std::string>& allowed = {});
  // Throws InvalidInput naming every item not consumed and listing the valid options.
  void finish() const;

 private:
  [[noreturn]] void fail(const std::string& what) const;
  const EngineSpec& spec_;
  std::vector<EngineOptionInfo> valid_;
  std::vector<bool> used_values_;
  bool word_used_ = false;
};

}  // namespace nlobs
