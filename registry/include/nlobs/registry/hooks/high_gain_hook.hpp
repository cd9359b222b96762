#pragma once
// The high-gain hook of register_model.hpp: a HighGainObserver<Model> ([HG-EMB23]) from a
// scenario's high_gain spec, for a model with one output and no input. The observability map
// comes from the model (Taylor-mode AD for N <= 8, ADOL-C beyond), or from the model's hand
// embedding when it has one: hand_embedding(const Model&) -> std::optional<Form>, found by
// argument-dependent lookup (nlobs/models/embedded_forms.hpp has the shipped ones).
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include "nlobs/observers/high_gain/high_gain_observer.hpp"
#include "nlobs/observers/high_gain/lie_observability_map.hpp"
#include "nlobs/observers/high_gain/taylor_observability_map.hpp"
#include "nlobs/registry/high_gain_spec.hpp"
#include "nlobs/solvers/engine_registry.hpp"

namespace nlobs::detail {

// The hand embedding's type, or void when the model has none.
template <typename Model>
struct HandEmbeddingOf {
  using type = void;
};
template <typename Model>
requires requires(const Model& m) {
  hand_embedding(m).has_value();
}
struct HandEmbeddingOf<Model> {
  using type = typename std::remove_cvref_t<decltype(hand_embedding(
      std::declval<const Model&>()))>::value_type;
};

template <typename Form>
constexpr bool has_alpha = requires(const Form f,
                                    const Eigen::Matrix<double, Form::kDimension, 1>& z) {
  f.alpha(z);
};
template <typename Form>
constexpr bool has_inverse = requires(const Form f,
                                      const Eigen::Matrix<double, Form::kDimension, 1>& z) {
  f.inverse(z);
};

template <typename Model>
std::unique_ptr<Observer> build_high_gain(Model model, const HighGainSpec& spec,
                                          const Eigen::VectorXd& start, double sample_time,
                                          const std::string& model_name) {
  using Form = typename HandEmbeddingOf<Model>::type;
  constexpr bool kHand = !std::is_void_v<Form>;
  const auto refuse = [&](const std::string& what) {
    throw InvalidInput("high_gain on model '" + model_name + "': " + what);
  };
  // The model's own form value: a form may hold the model's parameters.
  const auto hand = [&] {
    if constexpr (kHand) {
      return hand_embedding(model);
    } else {
      return std::optional<int>();
    }
  }();
  const bool hand_ok = hand.has_value();
  int N = spec.N;
  if constexpr (kHand) {
    if (N == 0) N = Form::kDimension;
  }
  if (N == 0) refuse("give 'N' (no hand-expanded embedding for this model)");
  const auto need_hand = [&](const char* what) {
    if (!hand_ok) {
      refuse(std::string(what) +
             " needs the model's hand-expanded embedding (hand_embedding(model); built in: "
             "duffing, oscillator, lorenz and van-der-pol at their documented parameters)");
    }
    if constexpr (kHand) {
      if (N != Form::kDimension) {
        refuse(std::string(what) + " exists for N = " + std::to_string(Form::kDimension) + " only");
      }
    }
  };
  HighGainDesign design;
  if (start.size() != Model::kStates) {
    refuse("'initial' must have " + std::to_string(Model::kStates) + " entries");
  }
  if (spec.initial_z && spec.initial_z->size() != N) {
    refuse("'initial_z' must have N = " + std::to_string(N) + " entries");
  }
  if (spec.map == "explicit") {
    need_hand("'map': explicit");
    if constexpr (kHand) design.map = std::make_shared<ExplicitObservabilityMap<Form>>(*hand);
  } else if (spec.map == "adolc" || (spec.map == "ad" && N > kMaxTaylorObservabilityOrder)) {
    design.map = std::make_shared<LieObservabilityMap>(model, N);
  } else {
    if (N > kMaxTaylorObservabilityOrder) {
      refuse("'map': taylor exists for N <= " + std::to_string(kMaxTaylorObservabilityOrder) +
             " (use ad or adolc)");
    }
    design.map = make_taylor_observability_map(model, N);
  }
  const bool hand_alpha = [&] {
    if constexpr (kHand) return has_alpha<Form> && hand_ok && N == Form::kDimension;
    return false;
  }();
  if (spec.map == "explicit" && (spec.alpha == "lie" || (spec.alpha == "auto" && !hand_alpha))) {
    refuse("α = L_f^N h needs a map built from the model ('map': ad, taylor or adolc)");
  }
  if (spec.alpha == "explicit" || (spec.alpha == "auto" && hand_alpha)) {
    if (!hand_alpha)
      refuse(
          "'alpha': explicit needs a hand α (the embedding's alpha(z); built in: duffing N = 6, "
          "oscillator N = 4)");
    if constexpr (kHand) {
      if constexpr (has_alpha<Form>) design.alpha = explicit_alpha<Form>(*hand);
    }
  }
  if (spec.inverse) {
    need_hand("'inverse'");
    if constexpr (kHand) {
      if constexpr (has_inverse<Form>) {
        design.inverse = explicit_inverse<Form>(*hand);
      } else {
        refuse("'inverse': the hand embedding has no inverse(z) (built in: the oscillator's)");
      }
    }
  }
  HighGainOptions o;
  o.sample_time = sample_time;
  o.theta = spec.theta;
  o.poles = spec.poles;
  o.coefficients = spec.coefficients;
  if (spec.saturation_p.size() || spec.saturation_box.size()) {
    SmoothSaturation s;
    s.R = spec.saturation_r;
    s.rho = spec.saturation_rho;
    if (spec.saturation_p.size()) {
      s.P = spec.saturation_p;
    } else {
      need_hand("'saturation.box'");
      if constexpr (kHand)
        s.P = saturation_weight_from_box(embedded_box_bound(*hand, spec.saturation_box));
    }
    o.saturation = s;
  }
  o.start = spec.start == "predicted" ? ProjectionStart::kPredicted : ProjectionStart::kPrevious;
  o.integrator = spec.integrator == "rk4"     ? HighGainIntegrator::kRk4
                 : spec.integrator == "cvode" ? HighGainIntegrator::kCvode
                                              : HighGainIntegrator::kAuto;
  o.substeps = spec.substeps;
  o.jump_threshold = spec.jump_threshold;
  o.observability_floor = spec.observability_floor;
  o.residual_scale = spec.residual_scale;
  o.restart_residual = spec.restart_residual;
  o.restart_every = spec.restart_every;
  o.name = spec.name;
  o.initial_estimate = start;
  o.initial_embedded_estimate = spec.initial_z;
  if (spec.initial_z_from) {
    if (spec.initial_z_from->size() != Model::kStates) {
      refuse("'initial_z_from' must have " + std::to_string(Model::kStates) + " entries");
    }
    Eigen::VectorXd z(N);
    if (!design.map->value(*spec.initial_z_from, z)) refuse("q_N('initial_z_from') is not finite");
    o.initial_embedded_estimate = z;
  }
  // The engine spec belongs to the scenario: built here through the registry, with the
  // projection's tolerances. An explicit inverse needs none. The options are checked first, so
  // that a bad engine spec does not hide a bad option (the constructor checks them again).
  o.design = std::move(design);
  o.validate();
  std::unique_ptr<Engine<Model::kStates>> projection;
  if (!o.design.inverse) {
    projection = EngineRegistry<Model::kStates>::global().create(spec.projection,
                                                                 high_gain_projection_options());
  }
  return std::make_unique<HighGainObserver<Model>>(std::move(model), std::move(o),
                                                   std::move(projection));
}

}  // namespace nlobs::detail
