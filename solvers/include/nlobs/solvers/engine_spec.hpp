#pragma once
// Engine spec strings: "name[:item[,item...]]", an item being "key=value" or a bare word
// (e.g. "steffensen", "anderson:m=3,damping=0.5", "newton:linesearch=1", "ceres:dogleg",
// "nlopt:LN_BOBYQA,xtol_rel=1e-6"). EngineSpecReader reads typed values and refuses anything
// the engine does not understand, listing what it does. An option's key is the name of the field
// it sets (NewtonOptions::line_search: line_search=1); the shorter names it had before are its
// aliases (linesearch=1), accepted alike; giving both is refused.
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
  std::string key;                     // "depth", "damping", ... ; for words: "<word>"
  std::string description;             // with the default
  std::vector<std::string> aliases{};  // older names of the key ("m"), accepted alike
};

// An engine as the registry and `nlobs list engines` show it: the name a spec starts with, one
// line on the method, its own options (the common ones are added by the registry) and example
// specs. Each built-in engine's options type gives its own (NewtonOptions::describe()).
struct EngineDescription {
  std::string name{};
  std::string description{};
  std::vector<EngineOptionInfo> options{};
  std::vector<std::string> examples{};
  // Common options (EngineRegistry::common_options) this engine does not take, by key: a spec
  // that gives one is refused as an unknown option instead of being ignored. An engine whose
  // library has stop tests of its own (the reference engines) lists those it does not map.
  std::vector<std::string> without_common{};
};

class EngineSpecReader {
 public:
  // `valid` lists the options of the engine: for error messages, and the aliases by which each
  // key may be given.
  EngineSpecReader(const EngineSpec& spec, std::vector<EngineOptionInfo> valid);
  // Each reads `key` or one of its aliases (InvalidInput when the spec gives more than one).

  std::optional<double> number(const std::string& key);
  // An integer in [min, max]; otherwise InvalidInput naming the key, the value and the range.
  std::optional<int> integer(const std::string& key, int min, int max);
  std::optional<bool> boolean(const std::string& key);  // 0/1, true/false, on/off
  std::optional<std::string> text(const std::string& key);
  // A word among `allowed` ("none", "jacobian"); otherwise InvalidInput naming the key as the
  // spec spells it, the value and the allowed words.
  std::optional<std::string> choice(const std::string& key,
                                    const std::vector<std::string>& allowed);
  // The single bare word, if any, which must be one of `allowed` (empty: any).
  std::optional<std::string> word(const std::vector<std::string>& allowed = {});
  // For an engine with a syntax of its own after its name (petsc:TYPE:-key=value:-flag): the
  // items no read took, as the spec wrote them — bare words, then key=value items, in order,
  // joined by ',' — all marked read. Empty when none is left.
  std::string rest();
  // Throws InvalidInput naming every item not consumed and listing the valid options.
  void finish() const;

 private:
  [[noreturn]] void fail(const std::string& what) const;
  // The spec item that sets `key` under its name or an alias, marked used; or nullopt.
  std::optional<std::size_t> find(const std::string& key);
  const EngineSpec& spec_;
  std::vector<EngineOptionInfo> valid_;
  std::vector<bool> used_values_;
  bool word_used_ = false;
};

}  // namespace nlobs
