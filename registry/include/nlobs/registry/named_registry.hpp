#pragma once
// Entries by name, each with the source that registered it ("built-in", a plugin's path, a
// test): the one mechanism behind the model, observer-type and problem-set registries. Names
// are unique across sources; the "valid: …" lists of error messages come from here, in the
// order the entries were added (the built-ins first, in their documented order).
#include <deque>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/common/printable.hpp"
#include "nlobs/common/registry_name.hpp"  // is_registry_name: the name rule of every registry

namespace nlobs {

// One key of an entry (a model parameter, an observer option): what `nlobs list` prints.
struct KeyInfo {
  std::string key;
  std::string meaning;
  std::string default_value;  // as text; empty: required (or no default)
};

template <typename Entry>
class NamedRegistry {
 public:
  // `kind` names the entries in messages: "model", "observer type", "problem set".
  explicit NamedRegistry(std::string kind) : kind_(std::move(kind)) {}

  // Throws InvalidInput for a name that breaks the registry name rule (registry_name.hpp:
  // 1 to 64 of [A-Za-z0-9_.+-]), or one already registered (naming both sources). Entry must
  // have a `name` member.
  void add(Entry entry, std::string source = "built-in") {
    const std::string& name = entry.name;
    if (!is_registry_name(name)) throw InvalidInput(registry_name_refusal(kind_, name, source));
    if (auto it = index_.find(name); it != index_.end()) {
      throw InvalidInput(kind_ + " '" + name + "' from " + printable(source) +
                         " is already registered by " + printable(entries_[it->second].second));
    }
    index_.emplace(name, entries_.size());
    entries_.emplace_back(std::move(entry), std::move(source));
  }

  const Entry* find(const std::string& name) const {
    auto it = index_.find(name);
    return it == index_.end() ? nullptr : &entries_[it->second].first;
  }
  // Throws std::invalid_argument "unknown <kind> 'x'; valid <kind>s: a, b, …".
  const Entry& get(const std::string& name) const {
    if (const Entry* e = find(name)) return *e;
    throw std::invalid_argument("unknown " + kind_ + " '" + printable(name, 60) + "'; valid " +
                                kind_ + "s: " + valid_list());
  }
  // The source that registered `name` (empty when none did).
  std::string source(const std::string& name) const {
    auto it = index_.find(name);
    return it == index_.end() ? std::string() : entries_[it->second].second;
  }
  bool contains(const std::string& name) const { return index_.count(name) > 0; }

  // In the order they were added.
  std::vector<const Entry*> entries() const {
    std::vector<const Entry*> out;
    for (const auto& [entry, source] : entries_) out.push_back(&entry);
    return out;
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& [entry, source] : entries_) out.push_back(entry.name);
    return out;
  }
  std::string valid_list() const {
    std::string list;
    for (const auto& [entry, source] : entries_) list += (list.empty() ? "" : ", ") + entry.name;
    return list;
  }
  const std::string& kind() const { return kind_; }

 private:
  std::string kind_;
  std::deque<std::pair<Entry, std::string>> entries_;  // a deque: find() pointers stay valid
  std::map<std::string, std::size_t> index_;
};

}  // namespace nlobs
