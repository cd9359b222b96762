// The sparse Jacobian of a scaled problem (scaling.hpp): ∂F̃(x̃) = D_f ∂F(x) D_u⁻¹ at
// x = D_u⁻¹ x̃, on the original's pattern — a row scaled by D_f,i and a column by 1/D_u,j, no
// entry added or dropped. A difference source is not scaled after the fact: its steps
// √ε·max(1, |x_j|) would be taken in the problem's variables, far too long for an unknown of
// order 1e-9 that the scaling brings to order 1; F̃ is differenced in x̃ instead, as the dense
// path differences the scaled problem. Out of line: the header stays free of Eigen's sparse
// module.
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "nlobs/solvers/box_bounds.hpp"
#include "nlobs/solvers/scaling.hpp"
#include "nlobs/solvers/sparse/compressed_jacobian.hpp"
#include "nlobs/solvers/sparse/sparse_jacobian.hpp"

namespace nlobs::detail {

std::shared_ptr<SparseJacobianState> scaled_sparse_jacobian_state(
    std::shared_ptr<SparseJacobianState> original, const Vector<Dynamic>& du,
    const Vector<Dynamic>& df, const BoxBounds& box, ScaledResidual scaled_f) {
  const Index n = du.size();
  Box<Dynamic> limits;
  limits.set(box, n);
  const Vector<Dynamic> inverse_du = du.cwiseInverse();
  // x = D_u⁻¹ x̃ inside the box, as the scaled F evaluates it.
  auto unscale = [inverse_du, limits](const Vector<Dynamic>& xs, Vector<Dynamic>& x) {
    x.resize(xs.size());
    for (Index i = 0; i < xs.size(); ++i) x[i] = limits.clamp(i, xs[i] * inverse_du[i]);
  };
  auto detect = [original, unscale, inverse_du, df, scaled_f = std::move(scaled_f)](
                    const Vector<Dynamic>& xs,
                    std::string& note) -> std::optional<SparseJacobianSource> {
    Vector<Dynamic> x;
    unscale(xs, x);
    const SparseJacobianSource* source = original->resolve(x);
    note = original->note();
    if (source == nullptr) return std::nullopt;
    // A source that evaluates F (differences, a user's that says it does): F̃ differenced in x̃.
    if (source->evaluations_per_jacobian > 0) {
      return difference_jacobian_source(scaled_f, *source->pattern);
    }
    SparseJacobianSource scaled;
    scaled.pattern = source->pattern;
    scaled.evaluations_per_jacobian = source->evaluations_per_jacobian;
    // The state's lock (the scaled one's, then the original's) guards these buffers.
    scaled.evaluate = [original, unscale, inverse_du, df, x = Vector<Dynamic>(),
                       f = Vector<Dynamic>()](const Vector<Dynamic>& at,
                                              const Vector<Dynamic>& f_scaled,
                                              SparseJacobian& jac) mutable {
      unscale(at, x);
      f = f_scaled.cwiseQuotient(df);  // F(x), as a source's evaluate takes it
      const int evaluations = original->evaluate(x, f, jac);
      for (Index i = 0; i < jac.outerSize(); ++i) {
        for (SparseJacobian::InnerIterator it(jac, i); it; ++it) {
          it.valueRef() *= df[i] * inverse_du[it.col()];
        }
      }
      return evaluations;
    };
    return scaled;
  };
  const bool declared = original->declared();
  return SparseJacobianState::detected_later(std::move(detect), declared);
}

}  // namespace nlobs::detail
