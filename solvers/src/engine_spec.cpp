#include "nlobs/solvers/engine_spec.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

namespace nlobs {

EngineSpec parse_engine_spec(std::string_view text) {
  EngineSpec spec;
  spec.text = std::string(text);
  const size_t colon = text.find(':');
  spec.name = std::string(text.substr(0, colon));
  if (spec.name.empty())
    throw InvalidInput("engine spec " + quoted_excerpt(spec.text) + " has no engine name");
  if (colon == std::string_view::npos) return spec;
  std::string_view rest = text.substr(colon + 1);
  while (true) {
    const size_t comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    if (item.empty())
      throw InvalidInput("engine spec " + quoted_excerpt(spec.text) + " has an empty item");
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos) {
      spec.words.emplace_back(item);
    } else {
      std::string key(item.substr(0, eq)), value(item.substr(eq + 1));
      if (key.empty() || value.empty()) {
        throw InvalidInput("engine spec " + quoted_excerpt(spec.text) + ": item " +
                           quoted_excerpt(item) + " needs key=value");
      }
      for (const auto& kv : spec.values) {
        if (kv.first == key) {
          throw InvalidInput("engine spec " + quoted_excerpt(spec.text) + " sets " +
                             quoted_excerpt(key) + " twice");
        }
      }
      spec.values.emplace_back(std::move(key), std::move(value));
    }
    if (comma == std::string_view::npos) break;
    rest = rest.substr(comma + 1);
  }
  return spec;
}

EngineSpecReader::EngineSpecReader(const EngineSpec& spec, std::vector<EngineOptionInfo> valid)
    : spec_(spec), valid_(std::move(valid)), used_values_(spec.values.size(), false) {
  // One name, one option: an alias repeated, or equal to another option's key, would let two
  // reads take the same item (an engine's registration bug, named here when it is created).
  std::vector<std::string> names;
  for (const auto& option : valid_) {
    names.push_back(option.key);
    names.insert(names.end(), option.aliases.begin(), option.aliases.end());
  }
  std::sort(names.begin(), names.end());
  if (const auto twice = std::adjacent_find(names.begin(), names.end()); twice != names.end()) {
    throw InvalidInput("engine '" + spec_.name + "' declares the option name " +
                       quoted_excerpt(*twice) + " twice (as a key or an alias)");
  }
}

void EngineSpecReader::fail(const std::string& what) const {
  std::ostringstream os;
  os << "engine spec " << quoted_excerpt(spec_.text) << ": " << what << "; valid options of '"
     << spec_.name << "': ";
  if (valid_.empty()) os << "(none)";
  for (size_t i = 0; i < valid_.size(); ++i) {
    os << (i ? ", " : "") << valid_[i].key;
    for (const auto& alias : valid_[i].aliases) os << " or " << alias;
    os << " (" << valid_[i].description << ")";
  }
  throw InvalidInput(os.str());
}

std::optional<std::size_t> EngineSpecReader::find(const std::string& key) {
  const auto known = std::find_if(valid_.begin(), valid_.end(),
                                  [&key](const EngineOptionInfo& o) { return o.key == key; });
  const auto names_key = [&](const std::string& given) {
    return given == key ||
           (known != valid_.end() &&
            std::find(known->aliases.begin(), known->aliases.end(), given) != known->aliases.end());
  };
  std::optional<std::size_t> found;
  for (std::size_t i = 0; i < spec_.values.size(); ++i) {
    if (!names_key(spec_.values[i].first)) continue;
    if (found) {
      fail(quoted_excerpt(spec_.values[*found].first) + " and " +
           quoted_excerpt(spec_.values[i].first) + " name the same option " + quoted_excerpt(key) +
           ": give one");
    }
    found = i;
  }
  if (found) used_values_[*found] = true;
  return found;
}

std::optional<std::string> EngineSpecReader::text(const std::string& key) {
  const auto i = find(key);
  if (!i) return std::nullopt;
  return spec_.values[*i].second;
}

std::optional<std::string> EngineSpecReader::choice(const std::string& key_name,
                                                    const std::vector<std::string>& allowed) {
  const auto i = find(key_name);
  if (!i) return std::nullopt;
  const auto& [key, value] = spec_.values[*i];
  if (std::find(allowed.begin(), allowed.end(), value) == allowed.end()) {
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
    fail(quoted_excerpt(key + "=" + value) + " is not one of: " + list);
  }
  return value;
}

std::optional<double> EngineSpecReader::number(const std::string& key_name) {
  const auto i = find(key_name);
  if (!i) return std::nullopt;
  const auto& [key, t] = spec_.values[*i];  // the key as the spec spells it, for messages
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(t.c_str(), &end);
  // ERANGE on underflow (a subnormal such as 4e-320, or 1e-400 rounded to 0) is a finite number
  // all the same: the option's own check judges its value. Only overflow is refused here.
  if (end == t.c_str() || *end != '\0' || !std::isfinite(v) ||
      (errno == ERANGE && std::fabs(v) > std::numeric_limits<double>::min())) {
    fail(quoted_excerpt(key + "=" + t) + " is not a finite number");
  }
  return v;
}

std::optional<int> EngineSpecReader::integer(const std::string& key_name, int min, int max) {
  const auto i = find(key_name);
  if (!i) return std::nullopt;
  const auto& [key, t] = spec_.values[*i];
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(t.c_str(), &end, 10);
  if (end == t.c_str() || *end != '\0') fail(quoted_excerpt(key + "=" + t) + " is not an integer");
  if (errno == ERANGE || v < min || v > max) {
    fail(quoted_excerpt(key + "=" + t) + " is out of range: must be in " + std::to_string(min) +
         ".." + std::to_string(max));
  }
  return static_cast<int>(v);
}

std::optional<bool> EngineSpecReader::boolean(const std::string& key_name) {
  const auto i = find(key_name);
  if (!i) return std::nullopt;
  const auto& [key, t] = spec_.values[*i];
  if (t == "1" || t == "true" || t == "on") return true;
  if (t == "0" || t == "false" || t == "off") return false;
  fail(quoted_excerpt(key + "=" + t) + " is not 0/1, true/false or on/off");
}

std::optional<std::string> EngineSpecReader::word(const std::vector<std::string>& allowed) {
  if (spec_.words.empty()) return std::nullopt;
  if (spec_.words.size() > 1) fail("more than one bare word");
  const std::string& w = spec_.words.front();
  if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), w) == allowed.end()) {
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
    fail(quoted_excerpt(w) + " is not one of: " + list);
  }
  word_used_ = true;
  return w;
}

std::string EngineSpecReader::rest() {
  std::string out;
  if (!word_used_) {
    for (const auto& w : spec_.words) out += (out.empty() ? "" : ",") + w;
    word_used_ = true;
  }
  for (size_t i = 0; i < spec_.values.size(); ++i) {
    if (used_values_[i]) continue;
    out += (out.empty() ? "" : ",") + spec_.values[i].first + "=" + spec_.values[i].second;
    used_values_[i] = true;
  }
  return out;
}

void EngineSpecReader::finish() const {
  std::string unknown;
  for (size_t i = 0; i < spec_.values.size(); ++i) {
    if (!used_values_[i])
      unknown += (unknown.empty() ? "" : ", ") + quoted_excerpt(spec_.values[i].first);
  }
  if (!word_used_) {
    for (const auto& w : spec_.words) unknown += (unknown.empty() ? "" : ", ") + quoted_excerpt(w);
  }
  if (!unknown.empty()) fail("unknown option(s) " + unknown);
}

}  // namespace nlobs
