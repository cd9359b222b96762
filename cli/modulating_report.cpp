#include "modulating_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "gnuplot.hpp"
#include "run_outputs.hpp"
#include "run_support.hpp"

namespace nlobs::cli {
void print_modulating_metrics(const ScenarioRun& run, std::ostream& out) {
  const RunResult& r = run.result;
  bool header = false;
  char line[256];
  for (size_t i = 0; i < r.metrics.size(); ++i) {
    const auto& m = run.figures[i].modulating;
    if (!m) continue;
    if (!header) {
      out << "canonical state (||eta - etahat||_2): max relative error from one horizon on, over "
             "the last 10 %, RMS after, Theorem 1 bound:\n";
      header = true;
    }
    std::snprintf(line, sizeof line, "  %-24s %10s %10s %10s %10s\n", r.metrics[i].name.c_str(),
                  fmt(m->rel_after_horizon).c_str(), fmt(m->final_rel).c_str(),
                  fmt(m->eta_rms_after).c_str(), fmt(m->max_bound).c_str());
    out << line;
  }
}

bool is_modulating_sweep(const std::string& key) {
  return key != "theta";
}

void run_modulating_sweep(const PreparedScenario& prepared, const std::string& key,
                          const std::vector<double>& values, const RunOptions& options,
                          std::ostream& out, std::ostream& err) {
  const Scenario& s = prepared.scenario;
  const bool observer_key = key == "horizon" || key == "sample_period";
  if (observer_key && std::none_of(s.observers.begin(), s.observers.end(),
                                   [&](const ObserverSpec& o) { return has_key(o, key); })) {
    throw std::invalid_argument("--sweep " + key + " needs a modulating observer in the scenario");
  }
  if (observer_key && key == "sample_period" &&
      std::none_of(s.observers.begin(), s.observers.end(), [](const ObserverSpec& o) {
        return has_key(o, "sample_period") &&
               observer_spec_json(o).value("sample_period", 0.0) > 0.0;
      })) {
    throw std::invalid_argument(
        "--sweep sample_period needs a modulating observer in sampled-data mode (sample_period "
        "> 0) in the scenario");
  }
  // (Data without the truth: the library's refusal, "--sweep needs simulated data (the truth)".)
  const SweepRun sweep = run_sweep(prepared, key, values, {.label = "--sweep"});
  std::ostringstream csv;
  csv << std::setprecision(10) << csv_field(key)
      << ",observer,x_rms_after,x2_rms_after,eta_rms_after,max_eta_rel_error_after_horizon,"
         "final_eta_rel_error,max_eta_bound,converged,failures,us_per_step,"
         "max_eta_error_after_horizon\n";
  char line[320];
  out << "sweep over " << key << " on scenario " << s.name << " (noise sigma " << s.noise
      << "); 'after' counts samples k >= " << sweep.settle_index
      << "; converged: final relative eta error < 1e-3\n";
  std::snprintf(line, sizeof line, "%-10s %-22s %11s %11s %11s %11s %11s %11s %5s %9s\n",
                key.c_str(), "observer", "x RMS", "x2 RMS", "eta RMS", "eta rel hor", "eta rel end",
                "bound", "conv", "us/step");
  out << line;
  struct Row {
    double value;
    std::string name;
    double x2, eta_abs, final_rel, bound;
  };
  std::vector<Row> rows;
  std::vector<std::string> names;
  for (const ObserverMetrics& m : sweep.values.front().result.metrics) names.push_back(m.name);
  for (const SweepValue& v : sweep.values) {
    const double value = v.value;
    const RunResult& r = v.result;
    for (size_t i = 0; i < r.metrics.size(); ++i) {
      const ObserverMetrics& m = r.metrics[i];
      const std::optional<ModulatingMetrics>& mm = v.figures[i].modulating;
      const double x_rms =
          m.mse_after_window.size() ? std::sqrt(m.mse_after_window.sum()) : std::nan("");
      const double x2_rms =
          m.mse_after_window.size() > 1 ? std::sqrt(m.mse_after_window[1]) : std::nan("");
      long failures = 0;
      for (const auto& [status, count] : m.failures) failures += count;
      const double eta_rms = mm ? mm->eta_rms_after : NAN, rel = mm ? mm->rel_after_horizon : NAN,
                   final_rel = mm ? mm->final_rel : NAN, bound = mm ? mm->max_bound : NAN;
      const char* converged = !mm ? "-" : (final_rel < 1e-3 ? "yes" : "no");
      std::snprintf(line, sizeof line, "%-10.4g %-22s %11s %11s %11s %11s %11s %11s %5s %9.2f\n",
                    value, m.name.c_str(), fmt(x_rms).c_str(), fmt(x2_rms).c_str(),
                    fmt(eta_rms).c_str(), fmt(rel).c_str(), fmt(final_rel).c_str(),
                    fmt(bound).c_str(), converged, m.ns_per_step / 1e3);
      out << line;
      csv << value << ',' << csv_field(m.name) << ',' << x_rms << ',' << x2_rms << ',' << eta_rms
          << ',' << rel << ',' << final_rel << ',' << bound << ',' << converged << ',' << failures
          << ',' << m.ns_per_step / 1e3 << ',' << (mm ? mm->abs_after_horizon : NAN) << '\n';
      rows.push_back({value, m.name, x2_rms, mm ? mm->abs_after_horizon : NAN, final_rel, bound});
    }
  }
  if (options.out_dir.empty()) return;
  std::ostringstream blocks;
  blocks << std::setprecision(10);
  for (const std::string& name : names) {
    blocks << "# " << gnuplot_comment_text(name) << ": " << gnuplot_comment_text(key)
           << " x2_rms_after max_eta_error_after_horizon final_eta_rel_error max_eta_bound\n";
    for (const auto& row : rows) {
      if (row.name != name) continue;
      blocks << row.value << ' ' << row.x2 << ' ' << row.eta_abs << ' ' << row.final_rel << ' '
             << row.bound << '\n';
    }
    blocks << "\n\n";
  }
  const bool positive = std::all_of(values.begin(), values.end(), [](double v) { return v > 0; });
  std::ostringstream g;
  // Only the observers that have the column's quantity (η, a bound) get a line for it.
  const auto has = [&](const std::string& name, double Row::*field) {
    return std::any_of(rows.begin(), rows.end(), [&](const Row& row) {
      return row.name == name && std::isfinite(row.*field);
    });
  };
  const auto series = [&](int column, const std::string& suffix, double Row::*field) {
    std::string text;
    for (size_t i = 0; i < names.size(); ++i) {
      if (!has(names[i], field)) continue;
      text += (text.empty() ? "" : ", ") + std::string("'sweep.dat' index ") + std::to_string(i) +
              " using 1:" + std::to_string(column) + " with linespoints title " +
              gnuplot_quoted(names[i] + suffix);
    }
    return text;
  };
  std::ostringstream title;
  title << key << " sweep: " << s.name << " (noise " << s.noise << ")";
  g << "set multiplot layout 2,1 title " << gnuplot_quoted(title.str()) << "\n"
    << (positive ? "set logscale xy\n" : "set logscale y\n") << "set grid\nset key outside right\n"
    << "set xlabel " << gnuplot_quoted(key)
    << "\nset ylabel 'RMS error of x2 (derivative) after settling'\nplot "
    << series(2, "", &Row::x2) << "\nset ylabel 'max ||eta - etahat|| from one horizon'\nplot "
    << series(3, "", &Row::eta_abs);
  const std::string bounds = series(5, " Theorem 1 bound", &Row::bound);
  if (!bounds.empty()) g << ", " << bounds;
  g << "\nunset multiplot\n";
  OutputDirectory dir(options.out_dir);
  write_sweep_files(dir, csv.str(), blocks.str(), g.str(), plot_timeout(options), out, err);
}

}  // namespace nlobs::cli
