#pragma once
// The PI observer banks of [FFMG19]'s examples, by name, for scenario files (docs/cli.md):
//   {"type": "pi_bank", "bank": "lander", "gains": [[6, 25], [49, 700]], ...}
// Users build their own banks with the C++ API (nlobs/observers/pi/pi_bank.hpp).
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "nlobs/observers/core/any_model.hpp"
#include "nlobs/observers/pi/pi_bank.hpp"

namespace nlobs::detail {

struct PiBankSpec {
  std::string bank;
  std::vector<PiGains> gains;                       // one pair per channel, in the bank's order
  std::vector<std::optional<double>> omega_bounds;  // N per channel (H2), null: not given
  std::string start = "paper";  // paper: γ(0) = 0; zero: (η̂, η̂₁)(0) = 0
  int substeps = 1;
  nlohmann::json parameters = nlohmann::json::object();  // the bank's model constants
};

struct PiBankInfo {
  std::string name, description;
  std::vector<std::string> channels;    // channel names, in order
  std::vector<std::string> parameters;  // "name=default"
  long states;                          // the model states the estimate covers
};
const std::vector<PiBankInfo>& pi_bank_catalog();
const PiBankInfo& pi_bank_info(const std::string& name);  // throws std::invalid_argument

// `where` prefixes errors. Checks the model's sizes against the bank.
std::unique_ptr<PiBankObserver> make_pi_bank(const PiBankSpec& spec, const AnyModel& model,
                                             const std::string& where);

}  // namespace nlobs::detail
