// Extending nlobs without editing it (docs/extending.md): a user's own accelerator and a
// user's own engine, used exactly like the built-in ones.
#include <cmath>
#include <cstdio>
#include <nlobs/solvers/solvers.hpp>
#include <string_view>

// 1. An accelerator: over-relaxed Picard, x_{k+1} = x_k + ω (G(x_k) − x_k).
//    It sees each evaluated pair (x, G(x)) and proposes the next point.
template <int N>
class OverRelaxation {
 public:
  explicit OverRelaxation(double omega = 1.0) : omega_(omega) {}
  std::string_view name() const { return "over-relaxation"; }
  void start(const nlobs::Vector<N>&) {}
  bool propose(const nlobs::Vector<N>& x, const nlobs::Vector<N>& gx, nlobs::Vector<N>& next,
               nlobs::Vector<N>& estimate) {
    next = x + omega_ * (gx - x);
    estimate = next;
    return true;  // every evaluation completes an iteration
  }

 private:
  double omega_;
};

// 2. An engine: the chord method, Newton with the Jacobian frozen at x0 (one factorisation,
//    linear convergence). It reuses the library's StopMonitor so the criteria mean the same.
template <int N>
class ChordEngine : public nlobs::Engine<N> {
 public:
  explicit ChordEngine(nlobs::SolverOptions options = {}) : nlobs::Engine<N>(options) {}
  std::string_view name() const override { return "chord"; }

  nlobs::Summary solve(const nlobs::FixedPointProblem<N>& problem, nlobs::Vector<N>& x) override {
    nlobs::detail::check_initial_guess(name(), problem, x);
    nlobs::Summary s;
    s.engine = name();
    nlobs::StopMonitor monitor(this->options().stop, x.template lpNorm<Eigen::Infinity>(),
                               /*estimate_lipschitz=*/false);
    nlobs::Matrix<N, N> j;
    problem.jacobian(x, j);       // needs a problem with a Jacobian (AD or user-supplied)
    j.diagonal().array() -= 1.0;  // ∂F = ∂G − I
    const Eigen::PartialPivLU<nlobs::Matrix<N, N>> lu(j);
    s.jacobian_evaluations = 1;
    nlobs::Vector<N> g;
    std::optional<nlobs::Status> status;
    double residual = 0.0;
    while (!status) {
      problem.evaluate(x, g);
      ++s.function_evaluations;
      const nlobs::Vector<N> f = g - x;
      residual = f.template lpNorm<Eigen::Infinity>();
      const nlobs::Vector<N> dx = -lu.solve(f);
      x += dx;
      status = monitor.update(dx.template lpNorm<Eigen::Infinity>(), residual,
                              x.template lpNorm<Eigen::Infinity>());
    }
    s.status = *status;
    monitor.fill(s, residual);
    s.record_answer(x, this->options().stop);  // what Summary::usable() judges by
    return s;
  }
};

int main() {
  // cos x = x, as a fixed-point problem with an AD Jacobian.
  const auto problem = nlobs::FixedPointProblem<1>::with_autodiff([](const auto& x) {
    using std::cos;
    using T = typename std::decay_t<decltype(x)>::Scalar;
    Eigen::Matrix<T, 1, 1> g;
    g[0] = cos(x[0]);
    return g;
  });
  nlobs::SolverOptions options;
  options.stop.step_tolerance = 1e-12;

  nlobs::AcceleratedEngine<1, OverRelaxation<1>> relaxed(options, OverRelaxation<1>(0.6));
  ChordEngine<1> chord(options);
  nlobs::PicardEngine<1> picard(options);

  int failures = 0;
  for (nlobs::Engine<1>* e :
       {static_cast<nlobs::Engine<1>*>(&relaxed), static_cast<nlobs::Engine<1>*>(&chord),
        static_cast<nlobs::Engine<1>*>(&picard)}) {
    nlobs::Vector<1> x(1.0);
    const nlobs::Summary s = e->solve(problem, x);
    std::printf("%-16s x = %.15f  %s\n", std::string(e->name()).c_str(), x[0],
                s.brief_report().c_str());
    failures += !(s.converged() && s.usable() && std::abs(x[0] - 0.739085133215161) < 1e-10);
  }
  return failures;
}
