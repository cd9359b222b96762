#pragma once
// Observability maps q_N(x) = [h, L_f h, …, L_f^{N−1} h] ([HG-EMB23]): the embedding a high-gain
// observer works in. One interface, two sources:
//   LieObservabilityMap        from the model's f and h by Taylor-mode AD (ADOL-C), any model;
//   ExplicitObservabilityMap   a map the user writes by hand, generic in its scalar (its
//                              Jacobian by ceres::Jet), e.g. the expansions in embedded_forms.hpp.
// Sizes are run-time here (N is an observer option); callers pass outputs of the right size,
// and then nothing allocates except inside ADOL-C's drivers.
#include <ceres/jet.h>

#include <Eigen/Core>
#include <string>

#include "nlobs/solvers/status.hpp"

namespace nlobs {

class ObservabilityMap {
 public:
  virtual ~ObservabilityMap() = default;
  virtual Eigen::Index states() const = 0;     // n
  virtual Eigen::Index dimension() const = 0;  // N
  virtual std::string description() const = 0;
  // z = q_N(x) (z has N entries). False when a value is not finite.
  virtual bool value(const Eigen::VectorXd& x, Eigen::VectorXd& z) const = 0;
  // ∂q_N/∂x (N×n). False when an entry is not finite.
  virtual bool jacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& dq) const = 0;
  // L_f^N h(x) = d/dt z_N along the model and its gradient: what an observer uses as α at x
  // when no explicit α(z) is known. Only maps built from the model have it.
  virtual bool has_next() const { return false; }
  virtual bool next(const Eigen::VectorXd& /*x*/, double& /*value*/,
                    Eigen::VectorXd* /*gradient*/) const {
    throw InvalidInput(description() + ": L_f^N h is not available (not built from the model)");
  }

 protected:
  // Throws InvalidInput naming the map when x is not of the state dimension.
  void check_states(const Eigen::VectorXd& x) const {
    if (x.size() != states()) {
      throw InvalidInput(description() + ": x must have " + std::to_string(states()) +
                         " entries, got " + std::to_string(x.size()));
    }
  }
};

// A hand-written map. Form (a struct, or a lambda with `auto` parameters is not enough — the
// sizes must be known):
//   struct MyMap {
//     static constexpr int kStates = n, kDimension = N;
//     template <typename T> Eigen::Matrix<T, N, 1> operator()(const Eigen::Matrix<T, n, 1>&) const;
//   };
template <typename Map>
class ExplicitObservabilityMap final : public ObservabilityMap {
 public:
  static constexpr int n = Map::kStates, N = Map::kDimension;
  explicit ExplicitObservabilityMap(Map map = {}, std::string description = "explicit q_N")
      : map_(std::move(map)), description_(std::move(description)) {}
  Eigen::Index states() const override { return n; }
  Eigen::Index dimension() const override { return N; }
  std::string description() const override { return description_; }
  bool value(const Eigen::VectorXd& x, Eigen::VectorXd& z) const override {
    check_states(x);
    z = map_(Eigen::Matrix<double, n, 1>(x));
    return z.allFinite();
  }
  bool jacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& dq) const override {
    check_states(x);
    using Jet = ceres::Jet<double, n>;
    Eigen::Matrix<Jet, n, 1> xj;
    for (int i = 0; i < n; ++i) xj[i] = Jet(x[i], i);
    const Eigen::Matrix<Jet, N, 1> zj = map_(xj);
    dq.resize(N, n);
    for (int j = 0; j < N; ++j) dq.row(j) = zj[j].v.transpose();
    return dq.allFinite();
  }
  const Map& map() const { return map_; }

 private:
  Map map_;
  std::string description_;
};

}  // namespace nlobs
