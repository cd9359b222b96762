#pragma once
// Models by name for scenarios: a JSON object
//   {"name": "lorenz", "parameters": {"sigma": 10}, "scheme": "rk4", "step": 0.01}
// becomes a discrete AnyModel. "modified-chua" defaults to the paper's forward Euler, T = 0.05.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "json_reader.hpp"
#include "nlobs/observers/core/any_model.hpp"

namespace nlobs::cli {

struct ModelInfo {
  std::string name;
  std::string description;
  std::vector<std::string> parameters;  // "alpha=10.82", ...
};

const std::vector<ModelInfo>& model_catalog();

// Throws std::invalid_argument naming the key path on any problem.
AnyModel make_model(JsonReader& spec);

}  // namespace nlobs::cli
