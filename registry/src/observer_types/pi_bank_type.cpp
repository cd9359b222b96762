// "pi_bank": the model-free PI observer banks of [FFMG19]'s examples (pi_banks.hpp), with the
// ultimate bounds of each channel reported before the run (nlobs/observers/pi/pi_bound.hpp).
#include <cmath>

#include "builtin_observer_types.hpp"
#include "nlobs/observers/pi/pi_bound.hpp"
#include "pi_banks.hpp"

namespace nlobs::detail {
namespace {

PiBankSpec parse(JsonReader& o, const ModelInstance&) {
  PiBankSpec s;
  s.bank = o.required_text("bank");
  PiBankInfo info;
  try {
    info = pi_bank_info(s.bank);
  } catch (const std::invalid_argument& e) {
    o.fail(e.what());
  }
  const Eigen::MatrixXd gains = o.matrix("gains").value_or(Eigen::MatrixXd());
  if (gains.cols() != 2 || gains.rows() != static_cast<Eigen::Index>(info.channels.size())) {
    o.fail("'gains' must list [k_p, k_i] for each of the bank's " +
           std::to_string(info.channels.size()) + " channel(s)");
  }
  for (Eigen::Index i = 0; i < gains.rows(); ++i) {
    const PiGains g{gains(i, 0), gains(i, 1)};
    try {
      validate(g, "channel '" + info.channels[static_cast<size_t>(i)] + "'");
    } catch (const InvalidInput& e) {
      o.fail(std::string("gains: ") + e.what());
    }
    s.gains.push_back(g);
  }
  s.omega_bounds.assign(info.channels.size(), std::nullopt);
  if (auto bounds = o.object("omega_bounds")) {
    for (size_t i = 0; i < info.channels.size(); ++i) {
      s.omega_bounds[i] = bounds->number(info.channels[i]);
      if (s.omega_bounds[i] && !(*s.omega_bounds[i] >= 0.0)) {
        bounds->fail("'" + info.channels[i] + "' must be >= 0");
      }
    }
    bounds->finish(info.channels);
  }
  s.start = o.text("start").value_or("paper");
  if (s.start != "paper" && s.start != "zero") {
    o.fail("'start' must be paper (gamma(0) = 0) or zero (estimates start at 0)");
  }
  s.substeps = static_cast<int>(o.integer("substeps", 1, 1000).value_or(1));
  if (auto parameters = o.object("parameters")) s.parameters = parameters->json();
  return s;
}

void write(const PiBankSpec& s, nlohmann::json& out) {
  out["bank"] = s.bank;
  nlohmann::json gains = nlohmann::json::array();
  for (const PiGains& g : s.gains) gains.push_back({g.kp, g.ki});
  out["gains"] = gains;
  const auto& channels = pi_bank_info(s.bank).channels;
  nlohmann::json bounds = nlohmann::json::object();
  for (size_t c = 0; c < channels.size(); ++c) {
    if (s.omega_bounds[c]) bounds[channels[c]] = *s.omega_bounds[c];
  }
  out["omega_bounds"] = bounds;
  out["start"] = s.start;
  out["substeps"] = s.substeps;
  out["parameters"] = s.parameters;
}

// Per channel: the gains, N, the paper's δ (eq. 15) and our ultimate bounds.
nlohmann::json report(const PiBankSpec& s, std::vector<std::string>* warnings) {
  nlohmann::json out = nlohmann::json::array();
  const auto& channels = pi_bank_info(s.bank).channels;
  for (size_t c = 0; c < channels.size(); ++c) {
    const std::optional<double> n = s.omega_bounds[c];
    const PiBound b = pi_ultimate_bound(s.gains[c], n.value_or(0.0));
    const std::string who = "pi:" + s.bank + " channel '" + channels[c] + "'";
    nlohmann::json j{{"observer", "pi:" + s.bank},
                     {"channel", channels[c]},
                     {"kp", s.gains[c].kp},
                     {"ki", s.gains[c].ki},
                     {"warnings", b.warnings}};
    if (n) {
      j["omega_bound"] = *n;
      j["paper_delta"] =
          std::isfinite(b.paper_delta) ? nlohmann::json(b.paper_delta) : nlohmann::json(nullptr);
      j["eta_error_bound"] = b.eta_error;
      j["error_norm_bound"] = b.error_norm;
    }
    for (const auto& w : b.warnings) warnings->push_back(who + ": " + w);
    out.push_back(j);
  }
  return out;
}

}  // namespace

void add_pi_bank_type(ObserverTypeRegistry& registry) {
  std::string banks;
  for (const auto& b : pi_bank_catalog()) {
    banks += "\n        " + b.name + ": " + b.description + "; channels";
    for (const auto& c : b.channels) banks += ' ' + c;
    if (!b.parameters.empty()) {
      banks += "; parameters";
      for (const auto& p : b.parameters) banks += ' ' + p;
    }
  }
  registry.add(observer_type_entry(ObserverTypeDefinition<PiBankSpec>{
      .name = "pi_bank",
      .description = "model-free PI observers of [FFMG19] (one output, the bank's states)",
      .condition = "the bank's states, one output",
      .keys = {{"bank", "which bank:" + banks, ""},
               {"gains", "[k_p, k_i] per channel", ""},
               {"omega_bounds", "{channel: N}, N >= |d eta / dt| (H2), for the bounds", "none"},
               {"start", "paper (gamma(0) = 0) | zero (estimates start at 0)", "paper"},
               {"substeps", "integration steps per sample, 1..1000", "1"},
               {"parameters", "the bank's model constants", "the bank's"}},
      .parse = parse,
      .write = write,
      .build = [](const PiBankSpec& s, const ObserverBuild& b) -> std::unique_ptr<Observer> {
        return make_pi_bank(s, b.model.discrete, b.where);
      },
      .report = report}));
}

}  // namespace nlobs::detail
