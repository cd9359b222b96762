#include "run_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "data_file.hpp"
#include "gnuplot.hpp"
#include "modulating_report.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "run_outputs.hpp"
#include "run_support.hpp"
#include "scenario.hpp"

namespace nlobs::cli {
namespace {

namespace fs = std::filesystem;

}  // namespace

nlohmann::json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

namespace {

nlohmann::json vector_or_null(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(number_or_null(v[i]));
  return a;
}

}  // namespace

std::string fmt(double v, const char* f) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

namespace {

// Observers that publish a per-sample solve residual (kSolveResidual: the MVT's ‖X(β)‖): its
// largest finite value over the run, or nothing for other observers.
std::optional<double> max_beta_residual(const RunResult& r, size_t i) {
  const auto row = signal_row(r.signal_info[i], SignalKind::kSolveResidual);
  if (!row) return std::nullopt;
  double worst = 0.0;
  for (Eigen::Index k = 0; k < r.signals[i].cols(); ++k) {
    const double v = r.signals[i](*row, k);
    if (std::isfinite(v)) worst = std::max(worst, v);
  }
  return worst;
}

}  // namespace

void add_coordinate_errors(const Measurements& data,
                           const std::vector<std::unique_ptr<Observer>>& observers, RunResult& r) {
  if (!data.has_truth()) return;
  for (size_t i = 0; i < observers.size(); ++i) {
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

std::optional<EmbeddedMetrics> embedded_metrics(const RunResult& r, size_t i) {
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

namespace {

void print_table(const Scenario& s, const Measurements& data, const RunResult& r,
                 std::ostream& out) {
  char line[512];
  out << "scenario " << s.name << ": " << data.steps() << " samples, noise sigma " << s.noise;
  if (s.process_noise > 0.0) out << ", process noise sigma " << s.process_noise;
  out << ", seed " << s.seed << "; 'after' counts samples k >= " << r.settle_index << "\n";
  std::snprintf(line, sizeof line, "%-26s %-11s %-11s %-11s %8s %6s %6s %9s %10s  %s\n", "observer",
                "MSE (all)", "MSE (after)", "paper MSE", "iter", "max", "first", "paper 1st",
                "us/step", "failures");
  out << line;
  for (const ObserverMetrics& m : r.metrics) {
    const double mse = m.mse.size() ? m.mse.mean() : NAN;
    const double after = m.mse_after_window.size() ? m.mse_after_window.mean() : NAN;
    double paper_mse = NAN, paper_first = NAN;
    if (auto it = s.reported.find(m.name); it != s.reported.end()) {
      if (it->second.count("mse")) paper_mse = it->second.at("mse");
      if (it->second.count("first_window_iterations")) {
        paper_first = it->second.at("first_window_iterations");
      }
    }
    std::string failures;
    for (const auto& [status, count] : m.failures) {
      failures += (failures.empty() ? "" : ", ") + status + " " + std::to_string(count);
    }
    std::snprintf(
        line, sizeof line, "%-26s %-11s %-11s %-11s %8s %6s %6s %9s %10.2f  %s\n", m.name.c_str(),
        fmt(mse).c_str(), fmt(after).c_str(), fmt(paper_mse, "%.4f").c_str(),
        m.solves ? fmt(m.iterations_mean, "%.1f").c_str() : "-",
        m.solves ? std::to_string(m.iterations_max).c_str() : "-",
        m.first_window_iterations >= 0 ? std::to_string(m.first_window_iterations).c_str() : "-",
        fmt(paper_first, "%.0f").c_str(), m.ns_per_step / 1e3,
        failures.empty() ? "none" : failures.c_str());
    out << line;
  }
  out << "MSE: mean over states of (1/K) sum_k (x_i[k] - xhat_i[k])^2 (paper eq. 92); per-state "
         "values in summary.json.\n";
  if (s.settle_time >= 0.0 && data.has_truth()) {
    out << "largest |x_i - xhat_i| for t >= " << s.settle_time
        << " s (the observed ultimate bound):\n";
    for (const ObserverMetrics& m : r.metrics) {
      std::snprintf(line, sizeof line, "  %-24s", m.name.c_str());
      out << line;
      for (Eigen::Index i = 0; i < m.max_error_after.size(); ++i) {
        out << " x" << i + 1 << " " << fmt(m.max_error_after[i]);
      }
      out << '\n';
    }
  }
  if (data.has_truth()) {
    out << "time from which ||x - xhat||_2 < 1e-3 to the end";
    bool any_residual = false;
    for (size_t i = 0; i < r.metrics.size(); ++i)
      any_residual |= max_beta_residual(r, i).has_value();
    out << (any_residual ? "; MVT: largest ||X(beta)||_2 over the run" : "") << ":\n";
    for (size_t i = 0; i < r.metrics.size(); ++i) {
      const long k = first_index_staying_below(data.x, r.estimates[i], 1e-3);
      std::snprintf(line, sizeof line, "  %-24s %s", r.metrics[i].name.c_str(),
                    k >= 0 ? ("t = " + fmt(data.t[k], "%.3f") + " s").c_str() : "never");
      out << line;
      if (const auto residual = max_beta_residual(r, i)) out << "   ||X|| " << fmt(*residual);
      out << '\n';
    }
  }
  bool header = false;
  for (size_t i = 0; i < r.metrics.size(); ++i) {
    const auto em = embedded_metrics(r, i);
    if (!em) continue;
    if (!header) {
      out << "embedded coordinates (||z - zhat||_2, z = q_N(x)): max ||zhat|| (peaking), below "
             "1e-6 from, final, RMS after, max projection residual after, jumps:\n";
      header = true;
    }
    std::snprintf(line, sizeof line, "  %-24s %10s  %-14s %10s %10s %10s %6.0f\n",
                  r.metrics[i].name.c_str(), fmt(em->max_zhat_norm).c_str(),
                  em->time_index_below >= 0
                      ? ("t = " + fmt(data.t[em->time_index_below], "%.3f") + " s").c_str()
                      : "never",
                  fmt(em->final_z_error).c_str(), fmt(em->z_rms_after).c_str(),
                  fmt(em->max_residual_after).c_str(), em->jumps);
    out << line;
  }
  for (const ObserverMetrics& m : r.metrics) {
    if (!m.first_failure.empty())
      out << "first failure of " << m.name << ": " << m.first_failure << '\n';
  }
}

void print_bounds(const nlohmann::json& bounds, std::ostream& out) {
  if (bounds.empty()) return;
  out << "PI ultimate bounds for |d eta/dt| <= N: paper delta (eq. 15, bounds ||E||) and ours "
         "(bound |eta - eta_hat| and ||E||; docs/observers.md):\n";
  for (const auto& b : bounds) {
    out << "  " << b["observer"].get<std::string>() << " " << b["channel"].get<std::string>()
        << " (k_p " << b["kp"].get<double>() << ", k_i " << b["ki"].get<double>() << "): ";
    if (!b.contains("omega_bound")) {
      out << "no N given\n";
      continue;
    }
    const auto num = [](const nlohmann::json& v) { return v.is_null() ? NAN : v.get<double>(); };
    out << "N " << fmt(num(b["omega_bound"])) << ", paper delta " << fmt(num(b["paper_delta"]))
        << ", |e| <= " << fmt(num(b["eta_error_bound"]))
        << ", ||E|| <= " << fmt(num(b["error_norm_bound"])) << '\n';
  }
}

nlohmann::json summary_json(const Scenario& s, const Measurements& data, const RunResult& r,
                            const std::string& source, const nlohmann::json& bounds,
                            const std::vector<std::string>& warnings,
                            const std::vector<long>& horizon_indices) {
  nlohmann::json observers = nlohmann::json::array();
  for (const ObserverMetrics& m : r.metrics) {
    nlohmann::json o{{"name", m.name},
                     {"engine", m.engine},
                     {"iterations_mean", m.iterations_mean},
                     {"iterations_max", m.iterations_max},
                     {"first_window_iterations", m.first_window_iterations},
                     {"evaluations_mean", m.evaluations_mean},
                     {"ns_per_step", m.ns_per_step},
                     {"failures", m.failures}};
    if (data.has_truth()) {
      o["mse"] = vector_or_null(m.mse);
      o["mse_after_window"] = vector_or_null(m.mse_after_window);
      o["max_error_after"] = vector_or_null(m.max_error_after);
    }
    if (!m.first_failure.empty()) o["first_failure"] = m.first_failure;
    const size_t i = observers.size();
    if (data.has_truth()) {
      const long k = first_index_staying_below(data.x, r.estimates[i], 1e-3);
      o["time_to_1e-3"] = k >= 0 ? nlohmann::json(data.t[k]) : nlohmann::json(nullptr);
    }
    if (const auto residual = max_beta_residual(r, i)) o["max_beta_residual"] = *residual;
    if (const auto em = embedded_metrics(r, i)) {
      o["max_zhat_norm"] = number_or_null(em->max_zhat_norm);
      o["time_to_z_1e-6"] = em->time_index_below >= 0 ? nlohmann::json(data.t[em->time_index_below])
                                                      : nlohmann::json(nullptr);
      o["final_z_error"] = number_or_null(em->final_z_error);
      o["z_rms_after"] = number_or_null(em->z_rms_after);
      o["max_projection_residual_after"] = number_or_null(em->max_residual_after);
      o["projection_jumps"] = em->jumps;
    }
    add_modulating_json(r, i, horizon_indices[i], o);
    observers.push_back(o);
  }
  nlohmann::json j{{"scenario", s.name}, {"steps", data.steps()},  {"noise_std", s.noise},
                   {"seed", s.seed},     {"observers", observers}, {"settle_index", r.settle_index},
                   {"source", source}};
  if (!data.stop_message.empty()) j["stop_message"] = data.stop_message;
  if (s.settle_time >= 0.0) j["settle_time"] = s.settle_time;
  if (s.process_noise > 0.0) j["process_noise_std"] = s.process_noise;
  if (!bounds.empty()) j["pi_bounds"] = bounds;
  if (!warnings.empty()) j["warnings"] = warnings;
  return j;
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

std::chrono::milliseconds plot_timeout(const RunOptions& options) {
  return std::chrono::milliseconds(static_cast<long long>(std::ceil(options.plot_timeout * 1e3)));
}

bool have_gnuplot() {
  return find_gnuplot().has_value();
}

Measurements simulate_scenario(const Scenario& s, const AnyModel& model) {
  SimulationOptions sim;
  sim.steps = s.steps;
  sim.noise_std = s.noise;
  sim.process_noise_std = s.process_noise;
  sim.seed = s.seed;
  sim.sample_time = model.sample_time() > 0 ? model.sample_time() : 1.0;
  sim.input = [&s, &model](long k) { return scenario_input(s, model, k); };
  return simulate(model, s.x0, sim);
}

std::vector<double> parse_sweep_values(const std::string& key, const std::string& list,
                                       bool positive) {
  std::vector<double> values;
  std::stringstream items(list);
  for (std::string item; std::getline(items, item, ',');) {
    size_t used = 0;
    double v = NAN;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v) || (positive && !(v > 0.0))) {
      throw std::invalid_argument("--sweep " + key + ": '" + item + "' is not a number" +
                                  (positive ? " > 0" : ""));
    }
    values.push_back(v);
  }
  if (values.empty()) throw std::invalid_argument("--sweep " + key + ": no values");
  return values;
}

namespace {

// --sweep theta=v1,v2,…: the high_gain observers once per θ on the same data ([HG-EMB23]'s
// peaking/noise trade-off: peaking grows as θ shrinks, noise amplification too). Other keys
// are the modulating-function sweeps (modulating_report.cpp).
void run_sweep(const Scenario& s, const ModelInstance& model, const Measurements& data,
               long settle_index, const RunOptions& options, std::ostream& out, std::ostream& err) {
  const std::string& spec = options.sweep;
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw std::invalid_argument("--sweep: expected KEY=v1,v2,... (got '" + spec + "')");
  }
  const std::string key = spec.substr(0, eq);
  if (is_modulating_sweep(key)) {
    // horizon and sample_period: > 0; a model parameter (the disturbance level a_max) may be 0.
    const std::vector<double> values =
        parse_sweep_values(key, spec.substr(eq + 1), key == "horizon" || key == "sample_period");
    run_modulating_sweep(s, key, values, data, settle_index, options, out, err);
    return;
  }
  const std::vector<double> values = parse_sweep_values(key, spec.substr(eq + 1), true);
  Scenario only = s;
  only.observers.clear();
  std::vector<size_t> index;  // of each swept observer in the scenario, for messages
  for (size_t i = 0; i < s.observers.size(); ++i) {
    if (!has_key(s.observers[i], "theta")) continue;
    only.observers.push_back(s.observers[i]);
    index.push_back(i);
  }
  if (only.observers.empty()) {
    throw std::invalid_argument("--sweep theta needs a high_gain observer in the scenario");
  }
  if (!data.has_truth()) throw std::invalid_argument("--sweep needs simulated data (the truth)");
  std::ostringstream csv;
  csv << std::setprecision(10)
      << "theta,observer,max_zhat_norm,z_rms_after,x_rms_after,time_to_z_1e-6,jumps,"
         "failures,us_per_step\n";
  char line[256];
  out << "sweep over theta on scenario " << s.name << " (noise sigma " << s.noise
      << "); 'after' counts samples k >= " << settle_index << "\n";
  std::snprintf(line, sizeof line, "%-8s %-20s %12s %12s %12s %14s %6s %9s\n", "theta", "observer",
                "max||zhat||", "z RMS after", "x RMS after", "z<1e-6 from", "jumps", "us/step");
  out << line;
  std::vector<std::string> names;
  struct Row {
    double theta;
    std::string name;
    double peak, z_rms, x_rms;
  };
  std::vector<Row> rows;
  for (double theta : values) {
    Scenario run = only;
    for (size_t i = 0; i < run.observers.size(); ++i) {
      run.observers[i] = with_key(run.observers[i], "theta", theta, model,
                                  s.name + ".observers[" + std::to_string(index[i]) + "]");
    }
    auto observers = make_observers(run, model, false);
    RunResult r = run_observers(data, observers, settle_index);
    make_names_unique(r);
    add_coordinate_errors(data, observers, r);
    if (names.empty()) {
      for (const ObserverMetrics& m : r.metrics) names.push_back(m.name);
    }
    for (size_t i = 0; i < observers.size(); ++i) {
      const auto em = embedded_metrics(r, i);
      const ObserverMetrics& m = r.metrics[i];
      // RMS of ‖x − x̂‖₂: the per-state mean squares summed over the states.
      const double x_rms =
          m.mse_after_window.size() ? std::sqrt(m.mse_after_window.sum()) : std::nan("");
      long failures = 0;
      for (const auto& [status, count] : m.failures) failures += count;
      const double t_below = em && em->time_index_below >= 0 ? data.t[em->time_index_below] : NAN;
      std::snprintf(line, sizeof line, "%-8.4g %-20s %12s %12s %12s %14s %6.0f %9.2f\n", theta,
                    m.name.c_str(), fmt(em ? em->max_zhat_norm : NAN).c_str(),
                    fmt(em ? em->z_rms_after : NAN).c_str(), fmt(x_rms).c_str(),
                    std::isfinite(t_below) ? ("t = " + fmt(t_below, "%.3f")).c_str() : "never",
                    em ? em->jumps : 0.0, m.ns_per_step / 1e3);
      out << line;
      rows.push_back(
          {theta, m.name, em ? em->max_zhat_norm : NAN, em ? em->z_rms_after : NAN, x_rms});
      csv << theta << ',' << csv_field(m.name) << ',' << (em ? em->max_zhat_norm : NAN) << ','
          << (em ? em->z_rms_after : NAN) << ',' << x_rms << ',' << t_below << ','
          << (em ? em->jumps : 0.0) << ',' << failures << ',' << m.ns_per_step / 1e3 << '\n';
    }
  }
  if (options.out_dir.empty()) return;
  // One block per observer (sweep.dat, gnuplot's index): sweep.csv interleaves them per θ.
  std::ostringstream blocks;
  blocks << std::setprecision(10);
  for (const std::string& name : names) {
    blocks << "# " << gnuplot_comment_text(name)
           << ": theta max_zhat_norm z_rms_after x_rms_after\n";
    for (const auto& row : rows) {
      if (row.name == name) {
        blocks << row.theta << ' ' << row.peak << ' ' << row.z_rms << ' ' << row.x_rms << '\n';
      }
    }
    blocks << "\n\n";
  }
  const auto series = [&](int column, const std::string& suffix) {
    std::string text;
    for (size_t i = 0; i < names.size(); ++i) {
      text += (i ? ", " : "") + std::string("'sweep.dat' index ") + std::to_string(i) +
              " using 1:" + std::to_string(column) + " with linespoints title " +
              gnuplot_quoted(names[i] + suffix);
    }
    return text;
  };
  std::ostringstream title, g;
  title << "theta sweep: " << s.name << " (noise " << s.noise << ")";
  g << "set multiplot layout 2,1 title " << gnuplot_quoted(title.str())
    << "\nset logscale xy\nset grid\nset key outside right\n"
    << "set xlabel 'theta'\nset ylabel 'max ||zhat|| (peaking)'\nplot " << series(2, "")
    << "\nset ylabel 'RMS error after settling'\nplot " << series(3, " z") << ", "
    << series(4, " x") << "\nunset multiplot\n";
  OutputDirectory dir(options.out_dir);
  write_sweep_files(dir, csv.str(), blocks.str(), g.str(), plot_timeout(options), out, err);
}

}  // namespace

void run_scenario(const std::string& name, const RunOptions& options, std::ostream& out,
                  std::ostream& err) {
  Scenario s = load_scenario(name);
  if (options.steps) {
    if (*options.steps < 1 || *options.steps > kMaxSteps) {
      throw std::invalid_argument("--steps " + std::to_string(*options.steps) +
                                  " is out of range: must be in 1.." + std::to_string(kMaxSteps));
    }
    s.steps = *options.steps;
  }
  if (options.noise) {
    if (!(*options.noise >= 0.0) || !std::isfinite(*options.noise)) {
      std::ostringstream os;
      os << "--noise " << *options.noise << " is not a finite number >= 0";
      throw std::invalid_argument(os.str());
    }
    s.noise = *options.noise;
  }
  if (options.seed) s.seed = *options.seed;
  if (!(options.plot_timeout > 0.0 && options.plot_timeout <= 86400.0)) {
    std::ostringstream os;
    os << "plot timeout " << options.plot_timeout << " s is out of range: must be in (0, 86400]";
    throw std::invalid_argument(os.str());
  }
  // Before any computation: a second run into the same --out fails now, not after its work.
  std::optional<OutputDirectoryLock> out_lock;
  if (!options.out_dir.empty()) out_lock.emplace(options.out_dir);
  const ModelInstance instance = scenario_model(s);
  const AnyModel& model = instance.discrete;

  Measurements data;
  std::string source = "simulation";
  if (options.data_file.empty()) {
    data = simulate_scenario(s, model);
    if (!data.stop_message.empty()) err << "nlobs: simulation " << data.stop_message << '\n';
    if (data.steps() == 0) throw std::runtime_error("the simulation produced no samples");
  } else {
    data = read_measurements_csv(options.data_file, model.outputs(), model.inputs(),
                                 options.allow_late);
    source = options.data_file;
  }

  if (!options.sweep.empty()) {
    long settle = -1;
    if (s.settle_time >= 0.0) {
      const double T = model.sample_time() > 0 ? model.sample_time() : 1.0;
      settle = static_cast<long>(
          std::min(std::ceil(s.settle_time / T - 1e-9), static_cast<double>(data.steps())));
    }
    run_sweep(s, instance, data, settle < 0 ? 0 : settle, options, out, err);
    return;
  }
  Eigen::Index longest = 1;
  auto observers = make_observers(s, instance, !options.out_dir.empty());
  for (const auto& o : observers) longest = std::max(longest, o->info().window);
  if (longest > data.steps()) {
    std::ostringstream os;
    os << "a window of " << longest << " samples is longer than the data (" << data.steps()
       << " samples)";
    throw std::invalid_argument(os.str());
  }

  long settle_index = -1;
  if (s.settle_time >= 0.0) {
    const double T = model.sample_time() > 0 ? model.sample_time() : 1.0;
    settle_index = static_cast<long>(
        std::min(std::ceil(s.settle_time / T - 1e-9), static_cast<double>(data.steps())));
  }
  std::vector<std::string> warnings;
  const nlohmann::json bounds = observer_reports(s, &warnings);
  for (const auto& o : observers) {
    for (const auto& w : o->info().warnings) warnings.push_back(w);
  }
  for (const auto& w : warnings) err << "nlobs: warning: " << w << '\n';

  const auto start = std::chrono::steady_clock::now();
  auto last = start;
  bool printed = false;
  RunResult r = run_observers(data, observers, settle_index, [&](long done, long total) {
    const auto now = std::chrono::steady_clock::now();
    if (now - start < std::chrono::seconds(1) ||
        (now - last < std::chrono::milliseconds(250) && done < total)) {
      return;
    }
    last = now;
    printed = true;
    err << "\rnlobs run " << s.name << ": " << (100 * done / total) << "% of " << total
        << " observer steps" << std::flush;
  });
  if (printed) err << '\n';
  make_names_unique(r);
  // What the run itself found (a window map that does not contract, a singular guess).
  for (const auto& o : observers) {
    for (const auto& w : o->info().warnings) {
      if (std::find(warnings.begin(), warnings.end(), w) != warnings.end()) continue;
      warnings.push_back(w);
      err << "nlobs: warning: " << w << '\n';
    }
  }
  add_coordinate_errors(data, observers, r);

  std::vector<long> horizon_indices;  // the first sample with a full window, per observer
  for (const auto& o : observers)
    horizon_indices.push_back(static_cast<long>(o->info().window) - 1);
  print_table(s, data, r, out);
  print_modulating_metrics(r, horizon_indices, out);
  print_bounds(bounds, out);

  if (!options.out_dir.empty()) {
    OutputDirectory dir(options.out_dir);  // summary.json removed: incomplete from here
    const std::vector<std::string> plots =
        write_run_files(dir, s, data, r, plot_timeout(options), warnings, err);
    dir.remove_stale_files();
    // Last: summary.json marks a complete output directory.
    dir.write("summary.json",
              summary_json(s, data, r, source, bounds, warnings, horizon_indices).dump(2) + "\n");
    out << "wrote " << (dir.path() / "summary.json").string()
        << ", trajectories.csv, plot_data.csv, scenario.json";
    for (const auto& p : plots) out << ", " << p;
    out << '\n';
  }
}

}  // namespace nlobs::cli
