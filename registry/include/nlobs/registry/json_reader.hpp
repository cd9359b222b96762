#pragma once
// Strict reading of JSON objects: every key must be known, every value of the right type, and
// an error names the file and the path ("scenario.json: observers[2].tol: expected a number").
#include <Eigen/Core>
#include <istream>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace nlobs {

// Scenario files are nested a few levels; a hostile one 70 000 levels deep must be refused at
// parse time, not crash the printer of an error message.
inline constexpr int kMaxJsonDepth = 64;
inline constexpr std::size_t kJsonExcerptLength = 80;

// Parses `in` (named `where` in errors): std::invalid_argument naming `where` for invalid JSON
// and for nesting deeper than kMaxJsonDepth (with the key under which it happened).
nlohmann::json parse_json(std::istream& in, const std::string& where);
// At most kJsonExcerptLength characters of a value's JSON text, for error messages.
std::string json_excerpt(const nlohmann::json& value);

class JsonReader {
 public:
  JsonReader(const nlohmann::json& object, std::string where);

  [[noreturn]] void fail(const std::string& what) const;
  const std::string& where() const { return where_; }
  bool has(const std::string& key) const { return object_.contains(key); }
  // The object this reader reads (to keep a sub-object as JSON, e.g. a model spec).
  const nlohmann::json& json() const { return object_; }

  std::optional<double> number(const std::string& key);
  // An integer in [min, max]; otherwise an error naming the key, the value and the range.
  std::optional<long> integer(const std::string& key, long min, long max);
  std::optional<bool> boolean(const std::string& key);
  std::optional<std::string> text(const std::string& key);
  // An observer's name: a string, not empty (reports key their rows and files on it).
  std::optional<std::string> name(const std::string& key = "name");
  std::optional<Eigen::VectorXd> vector(const std::string& key);
  // Bounds: an array of numbers where null is `unbounded` (−inf for lower, +inf for upper
  // bounds: JSON has no infinity).
  std::optional<Eigen::VectorXd> bounds(const std::string& key, double unbounded);
  // A matrix as an array of rows; a flat array is a column.
  std::optional<Eigen::MatrixXd> matrix(const std::string& key);
  std::optional<JsonReader> object(const std::string& key);
  std::vector<JsonReader> objects(const std::string& key);
  double required_number(const std::string& key);
  std::string required_text(const std::string& key);
  Eigen::VectorXd required_vector(const std::string& key);

  // Throws naming the first key nobody read, listing the valid ones.
  void finish(const std::vector<std::string>& valid) const;

 private:
  const nlohmann::json& get(const std::string& key);
  const nlohmann::json& object_;
  std::string where_;
  std::set<std::string> read_;
};

}  // namespace nlobs
