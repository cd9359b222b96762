#pragma once
// Polynomial unitary modulating functions ([MF-LTV], after Jouffroy and Reger; derivation in
// docs/observers.md). On the horizon s ∈ [0, T] (s = τ − (t − T)) the kernel φ_j of the
// canonical state η_j meets
//   φ_j⁽ᵏ⁾(0) = 0,     k = 0…r−1  (left modulating function of order r ≥ n)
//   φ_j⁽ᵏ⁾(T) = δ_kj,  k = 0…n−1  (unitary: the k-th derivative picks η_k out of the boundary)
// which a polynomial of degree d ≥ r + n − 1 can. At the minimal degree the kernel is unique;
// above it, the free coefficients minimise the noise gain
//   J_j = ∫₀ᵀ ( Σ_{i=0}^{n} (−1)^i ā_i φ_j⁽ⁱ⁾(s) )² ds,   ā_n = 1,
// the L2 norm of the kernel that multiplies the output y when the a_i are the constants ā_i
// (white noise on y enters η̂_j with this gain) — a linear least-squares problem solved with one
// of the library's engines. Everything here runs once, offline.
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>

#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/summary.hpp"

namespace nlobs {

struct ModulatingKernelOptions {
  int order = 0;   // r: derivatives below r vanish at the left end; 0 means n
  int degree = 0;  // d; 0 means the minimal r + n − 1 (no freedom left to optimise)
  // ā_0…ā_{n−1} of the noise cost (the constant or nominal coefficients); empty: zeros, which
  // minimises ∫ (φ⁽ⁿ⁾)².
  Eigen::VectorXd noise_weights;
};

// The solver options of the default design engine (Ceres): step tolerance 1e-14, 200
// iterations. Give an engine built from a spec the same (the CLI does):
// EngineRegistry<Eigen::Dynamic>::global().create(spec, modulating_kernel_solver_options()).
SolverOptions modulating_kernel_solver_options();

class ModulatingKernels {
 public:
  static constexpr int kMaxDegree = 29;  // the cost is integrated exactly by 30-point Gauss

  // n ≥ 1 canonical states, horizon T > 0; `engine` solves the noise-optimal kernel's least
  // squares above the minimal degree (none given: Ceres with modulating_kernel_solver_options();
  // it is used during the design only). Throws InvalidInput naming the option when r < n,
  // d < r + n − 1 or d > kMaxDegree, T is not finite and positive, the weights have the wrong
  // size or are not finite, the engine cannot do least squares, or the optimisation does not
  // converge.
  ModulatingKernels(int n, double horizon, ModulatingKernelOptions options = {},
                    std::unique_ptr<Engine<Eigen::Dynamic>> engine = nullptr);

  int states() const { return n_; }
  double horizon() const { return T_; }
  int order() const { return r_; }
  int degree() const { return d_; }
  // φ_j⁽ⁱ⁾(s) for j < n, i ≤ n (any i ≥ 0 works), s ∈ [0, T].
  double value(int j, int i, double s) const;
  // √J_j, the noise gain the options' weights define.
  double noise_gain(int j) const;
  // Coefficients in σ = s/T: φ_j(s) = Σ_k C(k, j) σ^k, (d+1) × n (long double: see the .cpp).
  const Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>& coefficients() const {
    return C_;
  }
  // The engine's summary of the last noise-optimal kernel (none at the minimal degree); its
  // `engine` is the engine's name, engine() the label of the spec it was made from.
  const std::optional<Summary>& optimisation() const { return summary_; }
  const std::string& engine() const { return engine_; }

 private:
  int n_, r_, d_;
  double T_;
  Eigen::VectorXd abar_;  // ā_0…ā_n
  Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic> C_;
  std::optional<Summary> summary_;
  std::string engine_;
};

}  // namespace nlobs
