#include "pi_banks.hpp"

#include <stdexcept>

#include "nlobs/registry/json_reader.hpp"

namespace nlobs::detail {
namespace {

using Values = PiBank::Values;

PiBank::Channel channel(PiBank::Signal measured, double a, PiBank::Function b, const PiGains& g,
                        const std::string& start) {
  PiBank::Channel c;
  c.measured = measured;
  c.a = a;
  c.b = std::move(b);
  c.gains = g;
  if (start == "zero") c.initial_estimates = Eigen::Vector2d::Zero();
  return c;
}

double parameter(JsonReader& p, const char* key, double fallback) {
  return p.number(key).value_or(fallback);
}

}  // namespace

const std::vector<PiBankInfo>& pi_bank_catalog() {
  static const std::vector<PiBankInfo> banks = {
      {"unknown-input", "example 3: f = dy/dt - u (a = 1, b = -u); estimate (y, f)", {"f"}, {}, 2},
      {"chua",
       "example 4: eta = x1 + x3 = dy/dt + y; x1' = eta_1 + b y, x3 = eta - x1 (the paper's "
       "reconstruction); estimate (x1, y, x3)",
       {"eta"},
       {"b=100/7", "x1_0=0"},
       3},
      {"chua-x3",
       "example 4 with x3' = -b y integrated and x1 = eta - x3 (no k_p/k_i lag term); "
       "estimate (x1, y, x3)",
       {"eta"},
       {"b=100/7", "x3_0=0"},
       3},
      {"lander",
       "example 5: x2 = dy/dt, x3 = sigma alpha u / (g - x2'), f = -x3' - sigma u; estimate "
       "(y, x2, x3, f)",
       {"x2", "f"},
       {"g=1.63", "sigma=50", "alpha=200"},
       4},
  };
  return banks;
}

const PiBankInfo& pi_bank_info(const std::string& name) {
  std::string list;
  for (const auto& b : pi_bank_catalog()) {
    if (b.name == name) return b;
    list += (list.empty() ? "" : ", ") + b.name;
  }
  throw std::invalid_argument("unknown PI bank '" + name + "'; valid: " + list);
}

std::unique_ptr<PiBankObserver> make_pi_bank(const PiBankSpec& spec, const AnyModel& model,
                                             const std::string& where) {
  const PiBankInfo& info = pi_bank_info(spec.bank);
  if (spec.gains.size() != info.channels.size()) {
    throw std::invalid_argument(where + ": bank '" + spec.bank + "' has " +
                                std::to_string(info.channels.size()) +
                                " channel(s), 'gains' lists " + std::to_string(spec.gains.size()));
  }
  if (model.states() != info.states || model.outputs() != 1) {
    throw std::invalid_argument(where + ": bank '" + spec.bank + "' estimates " +
                                std::to_string(info.states) +
                                " states from one output; the model '" + model.name() + "' has " +
                                std::to_string(model.states()) + " states and " +
                                std::to_string(model.outputs()) + " outputs");
  }
  if (!(model.sample_time() > 0.0)) {
    throw std::invalid_argument(where + ": a PI bank needs a model with a sample time");
  }
  JsonReader p(spec.parameters, where + ".parameters");
  PiBank bank(1, model.inputs());
  const PiBank::Signal y = bank.output(0);
  std::vector<PiBank::Signal> estimate;
  const std::string& start = spec.start;
  if (spec.bank == "unknown-input") {
    p.finish({});
    if (model.inputs() != 1) throw std::invalid_argument(where + ": needs a model with one input");
    const PiBank::Signal u = bank.input(0);
    const auto f =
        bank.add_pi("f", channel(
                             y, 1.0, [u](const Values& v) { return -v[u]; }, spec.gains[0], start));
    estimate = {y, f.eta};
  } else if (spec.bank == "chua" || spec.bank == "chua-x3") {
    const double b = parameter(p, "b", 100.0 / 7.0);
    const bool paper = spec.bank == "chua";
    const double start_value = parameter(p, paper ? "x1_0" : "x3_0", 0.0);
    p.finish({"b", paper ? "x1_0" : "x3_0"});
    const auto eta = bank.add_pi(
        "eta", channel(
                   y, 1.0, [y](const Values& v) { return v[y]; }, spec.gains[0], start));
    if (paper) {
      const auto x1 = bank.add_integrator(
          "x1", [=](const Values& v) { return v[eta.rate] + b * v[y]; }, start_value);
      const auto x3 = bank.add_signal("x3", [=](const Values& v) { return v[eta.eta] - v[x1]; });
      estimate = {x1, y, x3};
    } else {
      const auto x3 = bank.add_integrator(
          "x3", [=](const Values& v) { return -b * v[y]; }, start_value);
      const auto x1 = bank.add_signal("x1", [=](const Values& v) { return v[eta.eta] - v[x3]; });
      estimate = {x1, y, x3};
    }
  } else {  // lander
    const double g = parameter(p, "g", 1.63), sigma = parameter(p, "sigma", 50.0),
                 alpha = parameter(p, "alpha", 200.0);
    p.finish({"g", "sigma", "alpha"});
    if (model.inputs() != 1) throw std::invalid_argument(where + ": needs a model with one input");
    const PiBank::Signal u = bank.input(0);
    const auto x2 = bank.add_pi("x2", channel(y, 1.0, {}, spec.gains[0], start));
    // x2' = g − σαu/x3  ⇒  x3 = σαu / (g − x2'), with x2' estimated by the x2 channel's rate.
    const auto x3 = bank.add_signal(
        "x3", [=](const Values& v) { return sigma * alpha * v[u] / (g - v[x2.rate]); });
    // x3' = −σu − f  ⇒  f = −x3' − σu: a = −1, b = −σu on the signal x3.
    const auto f = bank.add_pi(
        "f", channel(
                 x3, -1.0, [=](const Values& v) { return -sigma * v[u]; }, spec.gains[1], start));
    estimate = {y, x2.eta, x3, f.eta};
  }
  return std::make_unique<PiBankObserver>(std::move(bank),
                                          PiBankOptions{.name = "pi:" + spec.bank,
                                                        .estimate = std::move(estimate),
                                                        .sample_time = model.sample_time(),
                                                        .substeps = spec.substeps});
}

}  // namespace nlobs::detail
