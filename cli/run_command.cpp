#include "run_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "gnuplot.hpp"
#include "modulating_report.hpp"
#include "nlobs/observers/core/simulation.hpp"
#include "nlobs/runs/scenario.hpp"
#include "nlobs/runs/scenario_run.hpp"
#include "nlobs/runs/sweep.hpp"
#include "run_outputs.hpp"
#include "run_support.hpp"

namespace nlobs::cli {

std::string fmt(double v, const char* f) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

namespace {

// The run's tables: what it measured and the figures run_prepared computed (nothing computed
// here).
void print_table(const ScenarioRun& run, std::ostream& out) {
  const Scenario& s = run.prepared.scenario;
  const Measurements& data = run.prepared.data;
  const RunResult& r = run.result;
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
    const bool any_residual =
        std::any_of(run.figures.begin(), run.figures.end(),
                    [](const ObserverFigures& f) { return f.max_beta_residual.has_value(); });
    out << (any_residual ? "; MVT: largest ||X(beta)||_2 over the run" : "") << ":\n";
    for (size_t i = 0; i < r.metrics.size(); ++i) {
      const ObserverFigures& f = run.figures[i];
      const long k = f.time_index_below_1e3;
      std::snprintf(line, sizeof line, "  %-24s %s", r.metrics[i].name.c_str(),
                    k >= 0 ? ("t = " + fmt(data.t[k], "%.3f") + " s").c_str() : "never");
      out << line;
      if (f.max_beta_residual) out << "   ||X|| " << fmt(*f.max_beta_residual);
      out << '\n';
    }
  }
  bool header = false;
  for (size_t i = 0; i < r.metrics.size(); ++i) {
    const auto& em = run.figures[i].embedded;
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

}  // namespace

std::chrono::milliseconds plot_timeout(const RunOptions& options) {
  return std::chrono::milliseconds(static_cast<long long>(std::ceil(options.plot_timeout * 1e3)));
}

bool have_gnuplot() {
  return find_gnuplot().has_value();
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
// are the modulating-function table (modulating_report.cpp); both run the library's sweep.
void run_sweep(const PreparedScenario& prepared, const RunOptions& options, std::ostream& out,
               std::ostream& err) {
  const Scenario& s = prepared.scenario;
  const Measurements& data = prepared.data;
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
    run_modulating_sweep(prepared, key, values, options, out, err);
    return;
  }
  const std::vector<double> values = parse_sweep_values(key, spec.substr(eq + 1), true);
  if (std::none_of(s.observers.begin(), s.observers.end(),
                   [](const ObserverSpec& o) { return has_key(o, "theta"); })) {
    throw std::invalid_argument("--sweep theta needs a high_gain observer in the scenario");
  }
  // (Data without the truth: the library's refusal, "--sweep needs simulated data (the truth)".)
  const SweepRun sweep =
      run_sweep(prepared, key, values, {.only_swept_observers = true, .label = "--sweep"});
  std::ostringstream csv;
  csv << std::setprecision(10)
      << "theta,observer,max_zhat_norm,z_rms_after,x_rms_after,time_to_z_1e-6,jumps,"
         "failures,us_per_step\n";
  char line[256];
  out << "sweep over theta on scenario " << s.name << " (noise sigma " << s.noise
      << "); 'after' counts samples k >= " << sweep.settle_index << "\n";
  std::snprintf(line, sizeof line, "%-8s %-20s %12s %12s %12s %14s %6s %9s\n", "theta", "observer",
                "max||zhat||", "z RMS after", "x RMS after", "z<1e-6 from", "jumps", "us/step");
  out << line;
  std::vector<std::string> names;
  for (const ObserverMetrics& m : sweep.values.front().result.metrics) names.push_back(m.name);
  struct Row {
    double theta;
    std::string name;
    double peak, z_rms, x_rms;
  };
  std::vector<Row> rows;
  for (const SweepValue& v : sweep.values) {
    const double theta = v.value;
    const RunResult& r = v.result;
    for (size_t i = 0; i < r.metrics.size(); ++i) {
      const std::optional<EmbeddedMetrics>& em = v.figures[i].embedded;
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
  if (!(options.plot_timeout > 0.0 && options.plot_timeout <= 86400.0)) {
    std::ostringstream os;
    os << "plot timeout " << options.plot_timeout << " s is out of range: must be in (0, 86400]";
    throw std::invalid_argument(os.str());
  }
  const ScenarioRequest request{.scenario = name,
                                .steps = options.steps,
                                .noise = options.noise,
                                .seed = options.seed,
                                .data_file = options.data_file,
                                .allow_late = options.allow_late};
  // Before any computation, once the scenario is known to be valid: a second run into the same
  // --out fails now, not after its work; a bad scenario leaves no directory behind.
  std::optional<OutputDirectoryLock> out_lock;
  std::string scenario_name = name;
  RunSettings settings;
  settings.parsed = [&](const Scenario& s) {
    scenario_name = s.name;
    if (!options.out_dir.empty()) out_lock.emplace(options.out_dir);
  };
  // (Reported before the run, which may then fail for want of samples.)
  const auto report_early_end = [&err](const PreparedScenario& prepared) {
    if (!prepared.data.stop_message.empty()) {
      err << "nlobs: simulation " << prepared.data.stop_message << '\n';
    }
  };
  if (!options.sweep.empty()) {
    const PreparedScenario prepared = prepare_request(request, std::move(settings));
    report_early_end(prepared);
    if (prepared.data.steps() == 0) throw std::runtime_error("the simulation produced no samples");
    run_sweep(prepared, options, out, err);
    return;
  }

  settings.trace_first_window = !options.out_dir.empty();
  settings.prepared = report_early_end;
  const auto start = std::chrono::steady_clock::now();
  auto last = start;
  bool printed = false;
  settings.progress = [&](long done, long total) {
    const auto now = std::chrono::steady_clock::now();
    if (now - start < std::chrono::seconds(1) ||
        (now - last < std::chrono::milliseconds(250) && done < total)) {
      return;
    }
    last = now;
    printed = true;
    err << "\rnlobs run " << scenario_name << ": " << (100 * done / total) << "% of " << total
        << " observer steps" << std::flush;
  };
  // (The progress line ends before a warning the run finds is printed.)
  settings.warning = [&err, &printed](const std::string& w) {
    if (printed) err << '\n';
    printed = false;
    err << "nlobs: warning: " << w << '\n';
  };
  ScenarioRun run = run_request(request, settings);  // the one call into the run layer
  if (printed) err << '\n';
  const Scenario& sc = run.prepared.scenario;
  const Measurements& data = run.prepared.data;
  print_table(run, out);
  print_modulating_metrics(run, out);
  print_bounds(run.observer_reports, out);

  if (!options.out_dir.empty()) {
    OutputDirectory dir(options.out_dir);  // summary.json removed: incomplete from here
    const std::vector<std::string> plots =
        write_run_files(dir, sc, data, run.result, plot_timeout(options), run.warnings, err);
    dir.remove_stale_files();
    // Last: summary.json marks a complete output directory.
    dir.write("summary.json", summary_json(run).dump(2) + "\n");
    out << "wrote " << (dir.path() / "summary.json").string()
        << ", trajectories.csv, plot_data.csv, scenario.json";
    for (const auto& p : plots) out << ", " << p;
    out << '\n';
  }
}

}  // namespace nlobs::cli
