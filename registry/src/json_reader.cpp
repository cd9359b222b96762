#include "nlobs/registry/json_reader.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

#include "nlobs/solvers/status.hpp"

namespace nlobs {

std::string json_excerpt(const nlohmann::json& value) {
  std::string text = value.dump();  // bounded: parse_json refuses deeper nesting
  if (text.size() > kJsonExcerptLength) text = text.substr(0, kJsonExcerptLength) + "...";
  return text;
}

nlohmann::json parse_json(std::istream& in, const std::string& where) {
  std::string last_key;
  const nlohmann::json::parser_callback_t limit =
      [&](int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
        if (event == nlohmann::json::parse_event_t::key) last_key = parsed.get<std::string>();
        if (depth >= kMaxJsonDepth) {  // the top level is depth 0
          throw std::invalid_argument(
              where + ": nested deeper than " + std::to_string(kMaxJsonDepth) + " levels" +
              (last_key.empty() ? "" : " (under key " + quoted_excerpt(last_key) + ")"));
        }
        return true;
      };
  try {
    return nlohmann::json::parse(in, limit);
  } catch (const nlohmann::json::parse_error& e) {
    throw std::invalid_argument(where + ": not valid JSON: " + e.what());
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond a double ("1e400", out_of_range.406): the key it came under says where.
    // The key read last: the number's own, or (in an array) the one before it.
    throw std::invalid_argument(
        where + ": " + (last_key.empty() ? "" : "near key " + quoted_excerpt(last_key) + ": ") +
        "a number is out of the range of a double (" + e.what() + ")");
  }
}

JsonReader::JsonReader(const nlohmann::json& object, std::string where)
    : object_(object), where_(std::move(where)) {
  if (!object_.is_object()) fail("expected an object");
}

void JsonReader::fail(const std::string& what) const {
  throw std::invalid_argument(where_ + ": " + what);
}

const nlohmann::json& JsonReader::get(const std::string& key) {
  read_.insert(key);
  return object_.at(key);
}

std::optional<double> JsonReader::number(const std::string& key) {
  if (!has(key)) return std::nullopt;
  const auto& v = get(key);
  if (!v.is_number() || !std::isfinite(v.get<double>())) {
    fail("'" + key + "' must be a finite number, got " + json_excerpt(v));
  }
  return v.get<double>();
}

std::optional<long> JsonReader::integer(const std::string& key, long min, long max) {
  if (!has(key)) return std::nullopt;
  const auto& v = get(key);
  if (!v.is_number_integer()) fail("'" + key + "' must be an integer, got " + json_excerpt(v));
  const auto out_of_range = [&] {
    fail("'" + key + "' = " + json_excerpt(v) + " is out of range: must be in " +
         std::to_string(min) + ".." + std::to_string(max));
  };
  // Unsigned JSON integers above LONG_MAX (2^63) would wrap when read as long.
  if (v.is_number_unsigned() &&
      v.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<long>::max())) {
    out_of_range();
  }
  const long value = v.get<long>();
  if (value < min || value > max) out_of_range();
  return value;
}

std::optional<bool> JsonReader::boolean(const std::string& key) {
  if (!has(key)) return std::nullopt;
  const auto& v = get(key);
  if (!v.is_boolean()) fail("'" + key + "' must be true or false, got " + json_excerpt(v));
  return v.get<bool>();
}

std::optional<std::string> JsonReader::text(const std::string& key) {
  if (!has(key)) return std::nullopt;
  const auto& v = get(key);
  if (!v.is_string()) fail("'" + key + "' must be a string, got " + json_excerpt(v));
  return v.get<std::string>();
}

std::optional<std::string> JsonReader::name(const std::string& key) {
  std::optional<std::string> s = text(key);
  if (s && s->empty()) fail("'" + key + "' must not be empty");
  return s;
}

std::optional<Eigen::VectorXd> JsonReader::vector(const std::string& key) {
  if (!has(key)) return std::nullopt;
  const auto& v = get(key);
  if (!v.is_array()) fail("'" + key + "' must be an array of numbers, got " + json_excerpt(v));
  Eigen::VectorXd out(static_cast<Eigen::Index>(v.size()));
  for (size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_number() || !std::isfinite(v[i].get<double>())) {
      fail("'" + key + "[" + std::to_string(i) + "]' must be a finite number, got " +
           json_excerpt(v[i]));
    }
    out[static_cast<Eigen::Index>(i)] = v[i].get<double>();
  }
  return out;
}

std::optional<Eigen::VectorXd> JsonReader::bounds(const std::string& key, double unbounded) {
  if (!has(key)) return std::nullopt;
  const auto& v = get(key);
  if (!v.is_array()) {
    fail("'" + key + "' must be an array of numbers or null, got " + json_excerpt(v));
  }
  Eigen::VectorXd out(static_cast<Eigen::Index>(v.size()));
  for (size_t i = 0; i < v.size(); ++i) {
    if (v[i].is_null()) {
      out[static_cast<Eigen::Index>(i)] = unbounded;
      continue;
    }
    if (!v[i].is_number()) {
      fail("'" + key + "[" + std::to_string(i) + "]' must be a number or null (no bound), got " +
           json_excerpt(v[i]));
    }
    out[static_cast<Eigen::Index>(i)] = v[i].get<double>();
  }
  return out;
}

std::optional<Eigen::MatrixXd> JsonReader::matrix(const std::string& key) {
  if (!has(key)) return std::nullopt;
  const auto& v = get(key);
  if (!v.is_array() || v.empty()) fail("'" + key + "' must be a non-empty array");
  if (!v[0].is_array()) {  // a column
    Eigen::MatrixXd out(static_cast<Eigen::Index>(v.size()), 1);
    for (size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_number()) fail("'" + key + "' must hold numbers or rows of numbers");
      out(static_cast<Eigen::Index>(i), 0) = v[i].get<double>();
    }
    return out;
  }
  const size_t cols = v[0].size();
  Eigen::MatrixXd out(static_cast<Eigen::Index>(v.size()), static_cast<Eigen::Index>(cols));
  for (size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_array() || v[i].size() != cols) {
      fail("'" + key + "' row " + std::to_string(i) + " must have " + std::to_string(cols) +
           " numbers");
    }
    for (size_t j = 0; j < cols; ++j) {
      if (!v[i][j].is_number() || !std::isfinite(v[i][j].get<double>())) {
        fail("'" + key + "[" + std::to_string(i) + "][" + std::to_string(j) +
             "]' must be a finite number");
      }
      out(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = v[i][j].get<double>();
    }
  }
  return out;
}

std::optional<JsonReader> JsonReader::object(const std::string& key) {
  if (!has(key)) return std::nullopt;
  const auto& v = get(key);
  if (!v.is_object()) fail("'" + key + "' must be an object, got " + json_excerpt(v));
  return JsonReader(v, where_ + "." + key);
}

std::vector<JsonReader> JsonReader::objects(const std::string& key) {
  std::vector<JsonReader> out;
  if (!has(key)) return out;
  const auto& v = get(key);
  if (!v.is_array()) fail("'" + key + "' must be an array of objects");
  for (size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_object()) fail("'" + key + "[" + std::to_string(i) + "]' must be an object");
    out.emplace_back(v[i], where_ + "." + key + "[" + std::to_string(i) + "]");
  }
  return out;
}

double JsonReader::required_number(const std::string& key) {
  if (!has(key)) fail("missing field '" + key + "'");
  return *number(key);
}

std::string JsonReader::required_text(const std::string& key) {
  if (!has(key)) fail("missing field '" + key + "'");
  return *text(key);
}

Eigen::VectorXd JsonReader::required_vector(const std::string& key) {
  if (!has(key)) fail("missing field '" + key + "'");
  return *vector(key);
}

void JsonReader::finish(const std::vector<std::string>& valid) const {
  for (auto it = object_.begin(); it != object_.end(); ++it) {
    if (!read_.count(it.key())) {
      std::string list;
      for (const auto& v : valid) list += (list.empty() ? "" : ", ") + v;
      fail("unknown key '" + it.key() + "'; valid keys: " + list);
    }
  }
}

}  // namespace nlobs
