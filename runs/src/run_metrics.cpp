#include "nlobs/runs/run_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

namespace nlobs {
namespace {

// Largest of a row over [from, K); NaN as soon as one entry is not finite.
double max_over(const Eigen::MatrixXd& e, Eigen::Index row, Eigen::Index from) {
  double worst = 0.0;
  if (from >= e.cols()) return NAN;
  for (Eigen::Index k = from; k < e.cols(); ++k) {
    const double v = e(row, k);
    if (!(v <= worst)) worst = v;  // NaN propagates
  }
  return worst;
}

}  // namespace

void make_names_unique(RunResult& r) {
  std::set<std::string> taken;
  for (const ObserverMetrics& m : r.metrics) taken.insert(m.name);
  std::set<std::string> seen;
  for (ObserverMetrics& m : r.metrics) {
    if (seen.insert(m.name).second) continue;
    std::string renamed;
    for (int copy = 2; renamed.empty() || taken.count(renamed); ++copy) {
      renamed = m.name + " #" + std::to_string(copy);
    }
    taken.insert(renamed);
    seen.insert(renamed);
    m.name = renamed;
  }
}

void add_coordinate_errors(const Measurements& data,
                           const std::vector<std::unique_ptr<Observer>>& observers, RunResult& r) {
  if (!data.has_truth()) return;
  for (std::size_t i = 0; i < observers.size(); ++i) {
    const auto& info = r.signal_info[i];
    std::vector<Eigen::Index> rows = signal_rows(info, SignalKind::kEmbeddedEstimate);
    const bool canonical = rows.empty();
    if (canonical) rows = signal_rows(info, SignalKind::kCanonicalEstimate);
    // The observer's coordinates of the truth: its (or the user's model's) code, which may
    // throw anything; that sample's error is then unknown (NaN), as for a size that does not
    // match.
    const auto coordinates = [&](Eigen::Index k) -> Eigen::VectorXd {
      try {
        return observers[i]->coordinates_at(data.x.col(k), data.t[k]);
      } catch (...) {
        return Eigen::VectorXd::Constant(1, NAN);  // not empty: the observer has coordinates
      }
    };
    // Nothing to compare with (no coordinates_at), or done already (a second call).
    if (rows.empty() || data.steps() == 0 || coordinates(0).size() == 0 ||
        signal_row(info, canonical ? SignalKind::kCanonicalError : SignalKind::kEmbeddedError)) {
      continue;
    }
    const Eigen::Index K = data.steps();
    const auto size = static_cast<Eigen::Index>(rows.size());
    Eigen::MatrixXd& signals = r.signals[i];
    const Eigen::Index added = canonical ? 2 : 1, at = signals.rows();
    signals.conservativeResize(at + added, Eigen::NoChange);
    Eigen::VectorXd estimate(size);
    for (Eigen::Index k = 0; k < K; ++k) {
      const Eigen::VectorXd z = coordinates(k);
      for (Eigen::Index j = 0; j < size; ++j) {
        estimate[j] = signals(rows[static_cast<size_t>(j)], k);
      }
      // An observer whose coordinates_at() does not match its published estimate: NaN.
      signals(at, k) = z.size() == size ? (z - estimate).norm() : NAN;
      if (canonical) signals(at + 1, k) = z.size() == size ? z.norm() : NAN;
    }
    if (canonical) {
      r.signal_info[i].push_back({"eta_error", SignalKind::kCanonicalError});
      r.signal_info[i].push_back({"eta_norm", SignalKind::kCanonicalNorm});
    } else {
      r.signal_info[i].push_back({"z_error", SignalKind::kEmbeddedError});
    }
  }
}

RunResult measure_observers(const Measurements& data,
                            std::vector<std::unique_ptr<Observer>>& observers, long settle_index,
                            std::vector<long>& horizon_indices,
                            const std::function<void(long done, long total)>& progress) {
  RunResult r = run_observers(data, observers, settle_index, progress);
  make_names_unique(r);
  add_coordinate_errors(data, observers, r);
  horizon_indices.clear();
  for (const auto& o : observers)
    horizon_indices.push_back(static_cast<long>(o->info().window) - 1);
  return r;
}

std::optional<EmbeddedMetrics> embedded_metrics(const RunResult& r, std::size_t i) {
  const auto& info = r.signal_info[i];
  const auto error_row = signal_row(info, SignalKind::kEmbeddedError);
  const std::vector<Eigen::Index> z_rows = signal_rows(info, SignalKind::kEmbeddedEstimate);
  const auto residual_row = signal_row(info, SignalKind::kProjectionResidual);
  const auto jumps_row = signal_row(info, SignalKind::kJumpCount);
  if (!error_row || z_rows.empty()) return std::nullopt;
  const Eigen::MatrixXd& e = r.signals[i];
  const Eigen::Index K = e.cols(), row = *error_row;
  EmbeddedMetrics m;
  if (K == 0) return m;
  Eigen::VectorXd zhat(static_cast<Eigen::Index>(z_rows.size()));
  for (Eigen::Index k = 0; k < K; ++k) {
    for (Eigen::Index j = 0; j < zhat.size(); ++j) zhat[j] = e(z_rows[static_cast<size_t>(j)], k);
    const double norm = zhat.norm();
    if (!(norm <= m.max_zhat_norm)) m.max_zhat_norm = norm;  // NaN propagates
  }
  m.final_z_error = e(row, K - 1);
  for (Eigen::Index k = K - 1; k >= 0 && e(row, k) < 1e-6; --k) m.time_index_below = k;
  const Eigen::Index from = std::max<Eigen::Index>(r.settle_index, 0);
  if (from >= K) return m;  // nothing after the settle index: the "after" figures stay NaN
  double sum = 0.0, worst = 0.0;
  for (Eigen::Index k = from; k < K; ++k) {
    sum += e(row, k) * e(row, k);
    if (residual_row) {
      const double res = e(*residual_row, k);
      if (!(res <= worst)) worst = res;
    }
  }
  m.z_rms_after = std::sqrt(sum / static_cast<double>(K - from));
  if (residual_row) m.max_residual_after = worst;  // NaN for an observer without one
  if (jumps_row) m.jumps = e(*jumps_row, K - 1);
  return m;
}

std::optional<double> max_beta_residual(const RunResult& r, std::size_t i) {
  const auto row = signal_row(r.signal_info[i], SignalKind::kSolveResidual);
  if (!row) return std::nullopt;
  double worst = 0.0;
  for (Eigen::Index k = 0; k < r.signals[i].cols(); ++k) {
    const double v = r.signals[i](*row, k);
    if (std::isfinite(v)) worst = std::max(worst, v);
  }
  return worst;
}

std::optional<ModulatingMetrics> modulating_metrics(const RunResult& r, std::size_t i,
                                                    long horizon_index) {
  const auto error = signal_row(r.signal_info[i], SignalKind::kCanonicalError);
  const auto norm = signal_row(r.signal_info[i], SignalKind::kCanonicalNorm);
  if (!error || !norm) return std::nullopt;
  const Eigen::MatrixXd& e = r.signals[i];
  const Eigen::Index K = e.cols();
  ModulatingMetrics m;
  if (K == 0) return m;
  const double scale = e.row(*norm).maxCoeff();
  m.abs_after_horizon = max_over(e, *error, std::max<Eigen::Index>(horizon_index, 0));
  m.rel_after_horizon = m.abs_after_horizon / scale;
  m.final_rel = max_over(e, *error, K - std::max<Eigen::Index>(K / 10, 1)) / scale;
  const Eigen::Index from = std::max<Eigen::Index>(r.settle_index, 0);
  if (from < K) {
    m.eta_rms_after =
        std::sqrt(e.row(*error).tail(K - from).squaredNorm() / static_cast<double>(K - from));
  }
  if (const auto bound = signal_row(r.signal_info[i], SignalKind::kCanonicalBound)) {
    m.max_bound = max_over(e, *bound, 0);
  }
  return m;
}

std::vector<ObserverFigures> observer_figures(const Measurements& data, const RunResult& r,
                                              const std::vector<long>& horizon_indices) {
  std::vector<ObserverFigures> out(r.metrics.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    ObserverFigures& f = out[i];
    if (data.has_truth())
      f.time_index_below_1e3 = first_index_staying_below(data.x, r.estimates[i], 1e-3);
    f.max_beta_residual = max_beta_residual(r, i);
    f.embedded = embedded_metrics(r, i);
    f.modulating = modulating_metrics(r, i, i < horizon_indices.size() ? horizon_indices[i] : -1);
  }
  return out;
}

}  // namespace nlobs
