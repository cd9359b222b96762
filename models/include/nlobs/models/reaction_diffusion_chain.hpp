#pragma once
// A model of run-time size, for observers at scale: the bistable reaction–diffusion equation
// (Nagumo's) on a line of n cells with unit spacing, no flux at the ends, and p point sensors,
//   x_i' = D (x_{i−1} − 2 x_i + x_{i+1}) + ρ x_i (1 − x_i)(x_i − a),   i = 0 … n − 1,
//   x_{−1} = x_0, x_n = x_{n−1}  (no flux),
//   y_j = x_{s_j},  s_j = ⌊(j + 1/2) n / p⌋,  j = 0 … p − 1,
// the discrete Nagumo equation of [Kee87], a chain of coupled bistable cells whose fronts
// between the stable states 0 and 1 travel (1 invading 0 for a < 1/2) when D is not too small.
// The cell spacing is the unit: a larger n is a longer line, not a finer one, so for states in
// [0, 1] the diffusion's eigenvalues stay in [−4D, 0] and the reaction's derivative in
// [−ρ max(a, 1 − a), ρ (1 − a + a²)/3] at every n, and a fixed explicit step stays stable
// (classic RK4: h (4D + ρ) ≤ 2.7 suffices). ∂F/∂x is tridiagonal, so one RK4 step's Jacobian
// has bandwidth 4: what the EKF's sparse path exploits (observers/core/move_covariance.hpp).
// No input. Generic in the scalar (AD, sparsity tracing).
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "nlobs/common/invalid_input.hpp"
#include "nlobs/models/model.hpp"

namespace nlobs {

struct ReactionDiffusionChainParameters {
  long cells = 200;         // n ≥ 2
  long sensors = 4;         // p, 1 ≤ p ≤ n
  double coupling = 1.0;    // D ≥ 0
  double growth = 1.0;      // ρ ≥ 0
  double threshold = 0.25;  // a ∈ (0, 1): the unstable state between 0 and 1
  // Throws InvalidInput naming the field.
  void validate() const {
    const auto refuse = [](const char* field, const char* rule, double value) {
      std::ostringstream os;
      os << "ReactionDiffusionChainParameters: " << field << " = " << value
         << " is invalid: " << rule;
      throw InvalidInput(os.str());
    };
    if (cells < 2 || cells > kLargestChain) {
      refuse("cells", "must be an integer in [2, 1e7]", static_cast<double>(cells));
    }
    if (sensors < 1 || sensors > cells) {
      const std::string rule = "must be an integer in [1, cells = " + std::to_string(cells) + "]";
      refuse("sensors", rule.c_str(), static_cast<double>(sensors));
    }
    if (!(coupling >= 0.0) || !std::isfinite(coupling)) {
      refuse("coupling", "must be finite and >= 0", coupling);
    }
    if (!(growth >= 0.0) || !std::isfinite(growth))
      refuse("growth", "must be finite and >= 0", growth);
    if (!(threshold > 0.0 && threshold < 1.0)) refuse("threshold", "must lie in (0, 1)", threshold);
  }
  static constexpr long kLargestChain = 10'000'000;
};

class ReactionDiffusionChain {
 public:
  static constexpr int kStates = Eigen::Dynamic;
  static constexpr int kInputs = 0;
  static constexpr int kOutputs = Eigen::Dynamic;
  static constexpr bool kTracesSparsity = true;  // generic, coupling fixed (models/model.hpp)
  template <typename T>
  using State = ModelVector<T, Eigen::Dynamic>;
  template <typename T>
  using Output = ModelVector<T, Eigen::Dynamic>;
  using Input = ModelVector<double, 0>;

  explicit ReactionDiffusionChain(ReactionDiffusionChainParameters p = {}) : p_(p) {
    p_.validate();
    sensors_.resize(static_cast<std::size_t>(p_.sensors));
    for (long j = 0; j < p_.sensors; ++j) {
      sensors_[static_cast<std::size_t>(j)] =
          static_cast<Eigen::Index>((2 * j + 1) * p_.cells / (2 * p_.sensors));
    }
  }

  const ReactionDiffusionChainParameters& parameters() const { return p_; }
  Eigen::Index states() const { return static_cast<Eigen::Index>(p_.cells); }
  Eigen::Index inputs() const { return 0; }
  Eigen::Index outputs() const { return static_cast<Eigen::Index>(p_.sensors); }
  // s_j, the cell each output reads.
  const std::vector<Eigen::Index>& sensor_cells() const { return sensors_; }

  template <typename T>
  State<T> vector_field(const State<T>& x, const Input&, double) const {
    const Eigen::Index n = states();
    require_size(x.size());
    State<T> dx(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const T& left = x[i > 0 ? i - 1 : i];
      const T& right = x[i + 1 < n ? i + 1 : i];
      dx[i] = p_.coupling * (left - 2.0 * x[i] + right) +
              p_.growth * x[i] * (1.0 - x[i]) * (x[i] - p_.threshold);
    }
    return dx;
  }

  template <typename T>
  Output<T> h(const State<T>& x) const {
    require_size(x.size());
    Output<T> y(outputs());
    for (std::size_t j = 0; j < sensors_.size(); ++j)
      y[static_cast<Eigen::Index>(j)] = x[sensors_[j]];
    return y;
  }

  // A front at cell `position` of width `width` cells: x_i = 1/(1 + exp((i − position)/width)),
  // 1 to its left, 0 to its right (a state to start a run from).
  Eigen::VectorXd front(double position, double width) const {
    if (!std::isfinite(position) || !(width > 0.0) || !std::isfinite(width)) {
      std::ostringstream os;
      os << "ReactionDiffusionChain::front: position = " << position << ", width = " << width
         << ": need finite values and width > 0";
      throw InvalidInput(os.str());
    }
    Eigen::VectorXd x(states());
    for (Eigen::Index i = 0; i < x.size(); ++i) {
      x[i] = 1.0 / (1.0 + std::exp((static_cast<double>(i) - position) / width));
    }
    return x;
  }

 private:
  void require_size(Eigen::Index size) const {
    if (size != states()) {
      throw InvalidInput("ReactionDiffusionChain: a state of " + std::to_string(size) +
                         " entries for a chain of " + std::to_string(p_.cells) + " cells");
    }
  }
  ReactionDiffusionChainParameters p_;
  std::vector<Eigen::Index> sensors_;
};

}  // namespace nlobs
