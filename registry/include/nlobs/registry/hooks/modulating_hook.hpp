#pragma once
// The modulating hook of register_model.hpp: a ModulatingFunctionObserver<Form> ([MF-LTV]) on
// the canonical form a model supplies through modulating_form(const Model&), found by
// argument-dependent lookup (nlobs/models/modulating_forms.hpp has the shipped ones). A form
// with disturbance_gains() and disturbance_level() offers Theorem 1's bound.
#include <Eigen/Core>
#include <memory>
#include <utility>

#include "nlobs/observers/modulating/modulating_function_observer.hpp"
#include "nlobs/registry/modulating_spec.hpp"
#include "nlobs/solvers/engine_registry.hpp"

namespace nlobs::detail {

template <typename Model>
concept HasModulatingForm = requires(const Model& m) {
  modulating_form(m);
};

template <typename Form>
std::unique_ptr<Observer> build_modulating(Form form, const ModulatingSpec& spec,
                                           const Eigen::VectorXd& start, double sample_time) {
  ModulatingOptions o;
  o.name = spec.name;
  o.initial_estimate = start;
  o.sample_time = sample_time;
  o.horizon = spec.horizon;
  o.quadrature = spec.quadrature == "trapezoid" ? Quadrature::kTrapezoid : Quadrature::kSimpson;
  o.kernel.order = spec.order;
  o.kernel.degree = spec.degree;
  o.kernel.noise_weights = spec.noise_weights;
  if (o.kernel.noise_weights.size() == 0) {
    Vector<Form::n> a;
    Matrix<Form::n, Form::p> b;
    form.coefficients(0.0, a, b);
    o.kernel.noise_weights = a;
  }
  o.sample_period = spec.sample_period;
  o.resample = spec.resample;
  o.resample_max_gap = spec.resample_max_gap;
  if (spec.disturbance_bound) {
    if constexpr (requires {
                    form.disturbance_gains();
                    form.disturbance_level();
                  }) {
      o.disturbance_gains = form.disturbance_gains();
      o.disturbance_level = form.disturbance_level();
    } else {
      throw InvalidInput("'disturbance_bound': this model has no unknown disturbance");
    }
  }
  // The design engine from its spec after the options' own checks, so that a bad spec cannot
  // hide a bad option.
  o.validate();
  return std::make_unique<ModulatingFunctionObserver<Form>>(
      std::move(form), std::move(o),
      EngineRegistry<Eigen::Dynamic>::global().create(spec.engine,
                                                      modulating_kernel_solver_options()));
}

}  // namespace nlobs::detail
