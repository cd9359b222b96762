#pragma once
// An engine built for nlobs::Dynamic sizes serving a compile-time size N: the problem's G (or F)
// and Jacobian are seen through dynamic vectors and the answer copied back. The engine registry
// uses it so that one registration at Dynamic serves every size (EngineRegistry<N>::create
// falls back to it); it costs a copy of x per solve and of each point per evaluation, and the
// inner engine's own allocations, so register a fixed-size entry where that matters.
#include <algorithm>
#include <memory>
#include <utility>

#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/library_sizes.hpp"

namespace nlobs {

// At N = Dynamic it passes the problem through unchanged.
template <int N>
class DynamicSizeEngine final : public Engine<N> {
 public:
  // Throws InvalidInput for a null engine.
  explicit DynamicSizeEngine(std::unique_ptr<Engine<Dynamic>> engine)
      : Engine<N>(engine ? engine->options() : SolverOptions{}), engine_(std::move(engine)) {
    if (!engine_) throw InvalidInput("DynamicSizeEngine: the engine is null");
  }

  std::string_view name() const override { return engine_->name(); }
  bool least_squares() const override { return engine_->least_squares(); }
  bool needs_contraction() const override { return engine_->needs_contraction(); }
  bool accepts_bounds() const override { return engine_->accepts_bounds(); }
  bool accepts_strict_bounds() const override { return engine_->accepts_strict_bounds(); }
  bool accepts_scaling() const override { return engine_->accepts_scaling(); }
  Engine<Dynamic>& engine() { return *engine_; }

  Summary solve(const FixedPointProblem<N>& problem, Vector<N>& x) override;

  Summary solve_least_squares(const RootProblem<N, Dynamic>& problem, Vector<N>& x) override;

 private:
  void on_limit_evaluations(int max_evaluations) override {
    engine_->limit_evaluations(max_evaluations);
  }
  void on_set_record_trace(bool on) override { engine_->set_record_trace(on); }
  void on_set_bounds() override { engine_->set_bounds(this->bounds_); }
  void on_set_scaling() override { engine_->set_scaling(this->scaling_); }
  std::unique_ptr<Engine<Dynamic>> engine_;
};

template <int N>
Summary DynamicSizeEngine<N>::solve(const FixedPointProblem<N>& problem, Vector<N>& x) {
  if constexpr (N == Dynamic) {
    return engine_->solve(problem, x);
  } else {
    detail::check_initial_guess(name(), problem, x);
    // A map of the fixed-size problem (`member`: evaluate or residual), and a Jacobian
    // (jacobian or residual_jacobian), called on dynamic vectors. Copied element-wise: GCC 12
    // warns (-Warray-bounds) on Eigen's packet copy at N = 1.
    const auto values = [&problem](auto member) {
      return [&problem, member](const Vector<Dynamic>& at, Vector<Dynamic>& out) {
        const Vector<N> point = at;
        Vector<N> value = Vector<N>::Zero();
        (problem.*member)(point, value);
        out.resize(N);
        std::copy(value.data(), value.data() + N, out.data());
      };
    };
    const auto jacobians = [&problem](auto member) {
      return [&problem, member](const Vector<Dynamic>& at, Matrix<Dynamic, Dynamic>& jac) {
        const Vector<N> point = at;
        Matrix<N, N> j = Matrix<N, N>::Zero();
        (problem.*member)(point, j);
        jac.resize(N, N);
        std::copy(j.data(), j.data() + N * N, jac.data());
      };
    };
    const auto g = values(&FixedPointProblem<N>::evaluate);
    // The residual form F (FixedPointProblem::residual) goes along when the problem has one.
    const auto f = values(&FixedPointProblem<N>::residual);
    Vector<Dynamic> xd = x;
    Summary s;
    if (problem.has_jacobian()) {
      const auto dg = jacobians(&FixedPointProblem<N>::jacobian);
      const auto df = jacobians(&FixedPointProblem<N>::residual_jacobian);
      auto dynamic = FixedPointProblem<Dynamic>::with_jacobian(g, dg, N, problem.jacobian_source());
      s = engine_->solve(problem.has_residual() ? dynamic.with_residual(f, df) : dynamic, xd);
    } else {
      auto dynamic = FixedPointProblem<Dynamic>::from_map(g, N);
      s = engine_->solve(problem.has_residual() ? dynamic.with_residual(f) : dynamic, xd);
    }
    if (xd.size() == N) {
      x = xd;
    } else {
      s.answer_recorded = true;  // the engine returned a point of another size: not an answer
      s.point_finite = false;
    }
    return s;
  }
}

template <int N>
Summary DynamicSizeEngine<N>::solve_least_squares(const RootProblem<N, Dynamic>& problem,
                                                  Vector<N>& x) {
  if constexpr (N == Dynamic) {
    return engine_->solve_least_squares(problem, x);
  } else {
    detail::check_initial_guess(name(), problem.size(), x);
    const Index m = problem.residual_size();
    const auto f = [&problem, m](const Vector<Dynamic>& at, Vector<Dynamic>& out) {
      const Vector<N> point = at;
      out.resize(m);
      problem.evaluate(point, out);
    };
    Vector<Dynamic> xd = x;
    Summary s;
    if (problem.has_jacobian()) {
      const auto df = [&problem, m](const Vector<Dynamic>& at, Matrix<Dynamic, Dynamic>& jac) {
        const Vector<N> point = at;
        Matrix<Dynamic, N> j(m, N);
        problem.jacobian(point, j);
        jac = j;
      };
      s = engine_->solve_least_squares(
          RootProblem<Dynamic, Dynamic>::with_jacobian(f, df, N, m, problem.jacobian_source()), xd);
    } else {
      s = engine_->solve_least_squares(RootProblem<Dynamic, Dynamic>::from_map(f, N, m), xd);
    }
    if (xd.size() == N) {
      x = xd;
    } else {
      s.answer_recorded = true;  // the engine returned a point of another size: not an answer
      s.point_finite = false;
    }
    return s;
  }
}

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_DYNAMIC_SIZE_ENGINE(n) extern template class DynamicSizeEngine<n>;
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_DYNAMIC_SIZE_ENGINE)
#undef NLOBS_EXTERN_DYNAMIC_SIZE_ENGINE

}  // namespace nlobs
