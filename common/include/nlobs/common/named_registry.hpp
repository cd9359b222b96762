#pragma once
// Entries by name, each with the source that registered it ("built-in", a plugin's path, a
// test): the one mechanism behind every registry of nlobs — engines (EngineRegistry, at each
// size), models, observer types and problem sets.
//
// One name rule (registry_name.hpp: 1 to 64 of [A-Za-z0-9_.+-]); names unique across sources;
// one error type (InvalidInput) for a bad, taken or unknown name and for an incomplete entry
// (one without the function that builds it: an entry type says what its entries need with a
// function `std::string missing_part(const Entry&)`, found by argument-dependent lookup, that
// returns "has no factory" or empty); the "valid: …" lists of error messages in the order
// the entries were added (the built-ins first, in their documented order).
//
// Thread rule: every member may be called from any thread at any time, add() included. An
// entry, once added, is never changed, moved or removed: the pointers find() and entries()
// return stay valid for the registry's life. (Moving a whole registry is for its construction
// only and is not synchronised.)
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/common/printable.hpp"
#include "nlobs/common/registry_name.hpp"

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
  // `kind` names the entries in messages: "model", "observer type", "problem set", "engine".
  explicit NamedRegistry(std::string kind) : kind_(std::move(kind)) {}
  NamedRegistry(NamedRegistry&& other)
      : kind_(std::move(other.kind_)),
        entries_(std::move(other.entries_)),
        index_(std::move(other.index_)) {}

  // Why add(entry, source) would refuse `entry`, as the message it would throw; empty when it
  // would not. In this order: a name that breaks the rule, a name already registered (naming
  // both sources), an incomplete entry. The plugin loader checks a whole registration with it
  // before it adds anything.
  std::string refusal(const Entry& entry, const std::string& source) const {
    const std::string missing = missing_part_of(entry);  // the entry's code: outside the lock
    std::lock_guard<std::mutex> lock(mutex_);
    return refusal_locked(entry, source, missing);
  }

  // Throws InvalidInput with refusal()'s message; adds the entry otherwise. Entry must have a
  // `name` member.
  void add(Entry entry, std::string source = "built-in") {
    const std::string missing = missing_part_of(entry);
    std::lock_guard<std::mutex> lock(mutex_);
    if (std::string why = refusal_locked(entry, source, missing); !why.empty()) {
      throw InvalidInput(why);
    }
    index_.emplace(entry.name, entries_.size());
    entries_.emplace_back(std::move(entry), std::move(source));
  }

  const Entry* find(const std::string& name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = index_.find(name);
    return it == index_.end() ? nullptr : &entries_[it->second].first;
  }
  // Throws InvalidInput "unknown <kind> 'x'; valid <kind>s: a, b, …".
  const Entry& get(const std::string& name) const {
    if (const Entry* e = find(name)) return *e;
    throw InvalidInput(unknown_refusal(name, valid_list()));
  }
  // The message of get() for a name not found, with the valid names `valid` (a registry that
  // serves more than its own entries, EngineRegistry<N>, lists them all).
  std::string unknown_refusal(const std::string& name, const std::string& valid) const {
    return "unknown " + kind_ + " '" + printable(name, 60) + "'; valid " + kind_ + "s: " + valid;
  }
  // The source that registered `name` (empty when none did).
  std::string source(const std::string& name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = index_.find(name);
    return it == index_.end() ? std::string() : entries_[it->second].second;
  }
  bool contains(const std::string& name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return index_.count(name) > 0;
  }

  // In the order they were added.
  std::vector<const Entry*> entries() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<const Entry*> out;
    for (const auto& [entry, source] : entries_) out.push_back(&entry);
    return out;
  }
  std::vector<std::string> names() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out;
    for (const auto& [entry, source] : entries_) out.push_back(entry.name);
    return out;
  }
  std::string valid_list() const {
    std::string list;
    for (const auto& name : names()) list += (list.empty() ? "" : ", ") + name;
    return list;
  }
  const std::string& kind() const { return kind_; }

 private:
  static std::string missing_part_of(const Entry& entry) {
    if constexpr (requires { missing_part(entry); }) {
      return missing_part(entry);
    } else {
      return {};
    }
  }
  std::string refusal_locked(const Entry& entry, const std::string& source,
                             const std::string& missing) const {
    const std::string& name = entry.name;
    if (!is_registry_name(name)) return registry_name_refusal(kind_, name, source);
    const auto prefix = [&] { return kind_ + " '" + name + "' from " + printable(source); };
    if (auto it = index_.find(name); it != index_.end()) {
      return prefix() + " is already registered by " + printable(entries_[it->second].second);
    }
    return missing.empty() ? missing : prefix() + " " + missing;
  }

  std::string kind_;
  mutable std::mutex mutex_;
  std::deque<std::pair<Entry, std::string>> entries_;  // a deque: find() pointers stay valid
  std::map<std::string, std::size_t> index_;
};

}  // namespace nlobs
