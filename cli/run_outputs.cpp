#include "run_outputs.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <tuple>

#include "gnuplot.hpp"
#include "run_support.hpp"

namespace nlobs::cli {
namespace {

// One column of a run's tables: a row of a column-major matrix (a state of the truth or of an
// estimate, a published signal), or the distance |a - b| of two such rows (an estimate's error).
struct ColumnRef {
  const double* a = nullptr;
  Eigen::Index stride_a = 1;
  const double* b = nullptr;  // set: |a - b|
  Eigen::Index stride_b = 1;
  double at(Eigen::Index k) const {
    return b == nullptr ? a[k * stride_a] : std::abs(a[k * stride_a] - b[k * stride_b]);
  }
};

ColumnRef row_of(const Eigen::MatrixXd& m, Eigen::Index i) {
  return {m.data() + i, m.rows()};
}

// trajectories.csv's columns: t, the truth x1..xn (simulations), every observer's estimate,
// every observer's published signals; with `errors`, then |x_i - xhat_i| per observer and state.
ColumnTable run_table(const Measurements& data, const RunResult& r, bool errors,
                      std::vector<ColumnRef>& refs, std::string& header) {
  const Eigen::Index n = r.estimates.empty() ? data.x.rows() : r.estimates.front().rows();
  refs.clear();
  refs.push_back({data.t.data(), 1});
  header = "t";
  if (data.has_truth()) {
    for (Eigen::Index i = 0; i < n; ++i) {
      refs.push_back(row_of(data.x, i));
      header += ",x" + std::to_string(i + 1);
    }
  }
  // Observer names hold commas ("window:ceres,N=6"): RFC 4180 quoting keeps one field each.
  // (Appended in two steps: GCC 12's -Wrestrict misfires on "," + std::string.)
  const auto add_name = [&header](const std::string& name) {
    header += ',';
    header += csv_field(name);
  };
  for (size_t o = 0; o < r.estimates.size(); ++o) {
    for (Eigen::Index i = 0; i < n; ++i) {
      refs.push_back(row_of(r.estimates[o], i));
      add_name(r.metrics[o].name + ".x" + std::to_string(i + 1));
    }
  }
  for (size_t o = 0; o < r.signal_info.size(); ++o) {
    for (size_t e = 0; e < r.signal_info[o].size(); ++e) {
      refs.push_back(row_of(r.signals[o], static_cast<Eigen::Index>(e)));
      add_name(r.metrics[o].name + ".signal." + r.signal_info[o][e].name);
    }
  }
  if (errors && data.has_truth()) {
    for (size_t o = 0; o < r.estimates.size(); ++o) {
      for (Eigen::Index i = 0; i < n; ++i) {
        const ColumnRef x = row_of(data.x, i), e = row_of(r.estimates[o], i);
        refs.push_back({x.a, x.stride_a, e.a, e.stride_a});
        add_name(r.metrics[o].name + ".error.x" + std::to_string(i + 1));
      }
    }
  }
  return {static_cast<Eigen::Index>(refs.size()), data.steps(),
          [&refs](Eigen::Index j, Eigen::Index k) { return refs[static_cast<size_t>(j)].at(k); }};
}

void append_number(std::string& line, double v) {
  if (std::isnan(v)) {
    line += "nan";  // whatever its sign bit
    return;
  }
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 12);
  line.append(buf, result.ptr);
}

void write_row(std::ostream& out, std::string& line, const ColumnTable& table,
               const std::function<double(Eigen::Index)>& value) {
  line.clear();
  for (Eigen::Index j = 0; j < table.columns; ++j) {
    if (j > 0) line += ',';
    append_number(line, value(j));
  }
  line += '\n';
  out.write(line.data(), static_cast<std::streamsize>(line.size()));
}

// The step norm per iteration at the first window, one block per window estimator.
std::string first_window_csv(const RunResult& r, std::vector<std::string>* names) {
  std::ostringstream os;
  os << std::setprecision(12) << "# observer iteration step_norm\n";
  for (const auto& m : r.metrics) {
    if (!m.first_window || m.first_window->trace.empty()) continue;
    names->push_back(m.name);
    for (const TraceEntry& t : m.first_window->trace) {
      os << gnuplot_data_token(m.name) << ' ' << t.iteration << ' ' << std::max(t.step_norm, 1e-300)
         << '\n';
    }
    os << "\n\n";  // gnuplot index separator
  }
  return os.str();
}

}  // namespace

std::string csv_field(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';  // RFC 4180: a quote inside a quoted field is doubled
    out += c;
  }
  return out + "\"";
}

void write_csv_rows(std::ostream& out, const std::string& header, const ColumnTable& table) {
  out << header << '\n';
  std::string line;
  for (Eigen::Index k = 0; k < table.rows; ++k) {
    write_row(out, line, table, [&](Eigen::Index j) { return table.value(j, k); });
  }
}

void write_plot_rows(std::ostream& out, const std::string& header, const ColumnTable& table) {
  if (table.rows <= kPlotRows) {
    write_csv_rows(out, header, table);
    return;
  }
  out << header << '\n';
  const Eigen::Index spans = kPlotRows / 2;
  std::vector<double> low(static_cast<size_t>(table.columns)),
      high(static_cast<size_t>(table.columns));
  std::string line;
  for (Eigen::Index s = 0; s < spans; ++s) {
    const Eigen::Index first = s * table.rows / spans, last = (s + 1) * table.rows / spans - 1;
    for (Eigen::Index j = 1; j < table.columns; ++j) {
      double lo = NAN, hi = NAN;
      for (Eigen::Index k = first; k <= last; ++k) {
        const double v = table.value(j, k);
        if (std::isnan(v)) continue;
        lo = std::isnan(lo) ? v : std::min(lo, v);
        hi = std::isnan(hi) ? v : std::max(hi, v);
      }
      low[static_cast<size_t>(j)] = lo;
      high[static_cast<size_t>(j)] = hi;
    }
    low[0] = table.value(0, first);
    high[0] = table.value(0, last);
    write_row(out, line, table, [&](Eigen::Index j) { return low[static_cast<size_t>(j)]; });
    write_row(out, line, table, [&](Eigen::Index j) { return high[static_cast<size_t>(j)]; });
  }
}

namespace {

// One colour and dash pattern per observer, the same in every plot of a run: line style
// kFirstObserverStyle + o (the truth is black). Eight colours, then the same with dashes.
constexpr long kFirstObserverStyle = 100;

void define_observer_styles(std::ostream& g, long observers) {
  static const char* const kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                         "#9467bd", "#8c564b", "#e377c2", "#17becf"};
  for (long o = 0; o < observers; ++o) {
    g << "set style line " << kFirstObserverStyle + o << " lc rgb '" << kColours[o % 8] << "' dt "
      << 1 + (o / 8) % 5 << " lw 1.5\n";
  }
  g << "set style line 99 lc rgb 'black' lw 2\n";
}

std::string observer_style(long o) {
  return " ls " + std::to_string(kFirstObserverStyle + o);
}

// The states that get a panel in states.png and errors.png: all of them up to kMostPlottedStates,
// else that many evenly spaced from x1 to xn (a 150-cell chain asked Cairo for a 45 000-pixel
// image, which it refuses); the multiplot's title says which.
constexpr Eigen::Index kMostPlottedStates = 12;
std::vector<Eigen::Index> plotted_states(Eigen::Index n) {
  std::vector<Eigen::Index> out;
  const Eigen::Index panels = std::min(n, kMostPlottedStates);
  for (Eigen::Index j = 0; j < panels; ++j) {
    out.push_back(panels == 1 ? 0 : j * (n - 1) / (panels - 1));
  }
  return out;
}
std::string plotted_title(const std::vector<Eigen::Index>& plotted, Eigen::Index n) {
  if (static_cast<Eigen::Index>(plotted.size()) == n) return "";
  std::string t = " title 'x" + std::to_string(plotted.front() + 1);
  for (std::size_t j = 1; j < plotted.size(); ++j) t += ", x" + std::to_string(plotted[j] + 1);
  return t + " (" + std::to_string(plotted.size()) + " of " + std::to_string(n) +
         " states; trajectories.csv has all)'";
}

// The gnuplot script of the PNG plots (estimates vs truth, errors, signals, the first window's
// convergence), reading plot_data.csv (its columns: plot_table()). Every name from the scenario
// (observers, signals) goes into the script through gnuplot_quoted(); each PNG is written under
// its OutputDirectory::external() name, relative to the directory, where gnuplot runs.
std::string plot_script(OutputDirectory& dir, const Measurements& data, const RunResult& r,
                        const std::vector<std::string>& traced) {
  const Eigen::Index n = r.estimates.empty() ? 0 : r.estimates.front().rows();
  const std::vector<Eigen::Index> plotted = plotted_states(n);
  const Eigen::Index panels = static_cast<Eigen::Index>(plotted.size());
  const std::string multiplot_title = n > 0 ? plotted_title(plotted, n) : "";
  const long observers = static_cast<long>(r.metrics.size());
  const long offset = data.has_truth() ? n : 0;
  long signal_columns = 0;
  for (const auto& info : r.signal_info) signal_columns += static_cast<long>(info.size());
  const long first_error = 2 + offset + observers * n + signal_columns;  // |x - xhat| columns
  std::ostringstream g;
  g << "set datafile separator ','\nset key outside right\nset grid\n"
    << "set terminal pngcairo noenhanced size 1200," << 300 * std::max<Eigen::Index>(panels, 1)
    << "\n";
  define_observer_styles(g, observers);
  g << "set output " << gnuplot_quoted(dir.external("states.png")) << "\nset multiplot layout "
    << panels << ",1" << multiplot_title << "\n";
  for (const Eigen::Index i : plotted) {
    g << "set ylabel 'x" << i + 1 << "'\n";
    // The truth's range, widened to the finite estimates after the settle index (an estimate
    // that settles on a wrong state must show: the EKF's negative concentrations of
    // mhe-batch-reactor) but by at most three times the truth's span, plus a margin: an
    // estimate's transient spikes (a PI bank's pole crossing) and a diverging observer must
    // not flatten the comparison; errors.png shows them in full.
    if (data.has_truth() && data.x.cols() > 0) {
      const double truth_lo = data.x.row(i).minCoeff(), truth_hi = data.x.row(i).maxCoeff();
      const double reach =
          3.0 * std::max(truth_hi - truth_lo, 1e-3 * std::max(1.0, std::abs(truth_hi)));
      double lo = truth_lo, hi = truth_hi;
      for (const Eigen::MatrixXd& e : r.estimates) {
        for (Eigen::Index k = std::max<Eigen::Index>(r.settle_index, 0); k < e.cols(); ++k) {
          const double v = e(i, k);
          if (!std::isfinite(v)) continue;
          lo = std::min(lo, std::max(v, truth_lo - reach));
          hi = std::max(hi, std::min(v, truth_hi + reach));
        }
      }
      const double margin =
          std::max(0.5 * (truth_hi - truth_lo), 1e-3 * std::max(1.0, std::abs(truth_hi)));
      g << "set yrange [" << lo - margin << ":" << hi + margin << "]\n";
    }
    g << "plot ";
    if (data.has_truth())
      g << "'plot_data.csv' using 1:" << i + 2 << " with lines ls 99 title 'true', ";
    for (long o = 0; o < observers; ++o) {
      g << "'plot_data.csv' using 1:" << 2 + offset + o * n + i << " with lines"
        << observer_style(o) << " title " << gnuplot_quoted(r.metrics[static_cast<size_t>(o)].name)
        << (o + 1 < observers ? ", " : "\n");
    }
  }
  g << "unset multiplot\nset autoscale y\n";
  if (data.has_truth()) {
    // Each panel from 1e-16 to 1e3 times the truth's scale (its range, or its size when it is
    // constant): one diverging observer must not squeeze the others into a line. An observer
    // whose error leaves the panel is drawn clipped and says so in its key entry.
    g << "set output " << gnuplot_quoted(dir.external("errors.png")) << "\nset logscale y\n"
      << "set format y '1e%L'\nset multiplot layout " << panels << ",1" << multiplot_title << "\n";
    for (const Eigen::Index i : plotted) {
      const double lo = data.x.row(i).minCoeff(), hi = data.x.row(i).maxCoeff();
      const double size = std::max(std::abs(lo), std::abs(hi));
      const double spread = std::max(hi - lo, 1e-3 * size);
      const double scale = spread > 0.0 && std::isfinite(spread) ? spread : 1.0;
      const double top = 1e3 * scale;
      g << "set yrange [" << 1e-16 * scale << ":" << top << "]\nset ylabel '|x" << i + 1
        << " - xhat" << i + 1 << "|'\nplot ";
      for (long o = 0; o < observers; ++o) {
        const Eigen::ArrayXd error =
            (data.x.row(i) - r.estimates[static_cast<size_t>(o)].row(i)).array().abs();
        const bool left = !(error.isFinite().all() && error.maxCoeff() <= top);
        g << "'plot_data.csv' using 1:($" << first_error + o * n + i << "+1e-16) with lines"
          << observer_style(o) << " title "
          << gnuplot_quoted(r.metrics[static_cast<size_t>(o)].name +
                            (left ? " (beyond the panel)" : ""))
          << (o + 1 < observers ? ", " : "\n");
      }
    }
    g << "unset multiplot\nunset logscale y\nset format y '% h'\nset autoscale y\n";
  }
  // Further signals of observers that publish them (PI banks: η̂, η̂₁ per channel, ...).
  long column = 2 + offset + observers * n;
  for (size_t o = 0; o < r.signal_info.size(); ++o) {
    const auto& info = r.signal_info[o];
    if (info.empty()) continue;
    const std::string file = "signals_" + std::to_string(o + 1) + ".png";
    g << "set terminal pngcairo noenhanced size 1200," << 250 * info.size() << "\nset output "
      << gnuplot_quoted(dir.external(file)) << "\nset multiplot layout " << info.size()
      << ",1 title " << gnuplot_quoted(r.metrics[o].name) << "\n";
    for (const auto& signal : info) {
      g << "set ylabel " << gnuplot_quoted(signal.name)
        << "\nplot 'plot_data.csv' using 1:" << column++ << " with lines notitle\n";
    }
    g << "unset multiplot\n";
  }
  // [HG-EMB23]'s Figs. 3 and 6 (‖z − ẑ‖) and [MF-LTV]'s canonical error ‖η − η̂‖ on a log scale.
  for (const auto& [kind, file, label] :
       {std::tuple<SignalKind, const char*, const char*>{SignalKind::kEmbeddedError, "z_error.png",
                                                         "||z - zhat||_2"},
        {SignalKind::kCanonicalError, "eta_error.png", "||eta - etahat||_2"}}) {
    std::vector<std::pair<long, std::string>> columns;
    std::vector<long> style_of;  // the observer of each column
    for (size_t o = 0, c = static_cast<size_t>(2 + offset + observers * n);
         o < r.signal_info.size(); c += r.signal_info[o].size(), ++o) {
      if (const auto row = signal_row(r.signal_info[o], kind)) {
        columns.emplace_back(static_cast<long>(c) + *row, r.metrics[o].name);
        style_of.push_back(static_cast<long>(o));
      }
    }
    if (columns.empty()) continue;
    g << "set terminal pngcairo noenhanced size 1000,600\nset output "
      << gnuplot_quoted(dir.external(file)) << "\nset logscale y\nset xlabel 't'\nset ylabel "
      << gnuplot_quoted(label) << "\nplot ";
    for (size_t i = 0; i < columns.size(); ++i) {
      g << "'plot_data.csv' using 1:($" << columns[i].first << "+1e-16) with lines"
        << observer_style(style_of[i]) << " title " << gnuplot_quoted(columns[i].second)
        << (i + 1 < columns.size() ? ", " : "\n");
    }
    g << "unset logscale y\nunset xlabel\n";
  }
  if (!traced.empty()) {
    g << "set datafile separator whitespace\nset terminal pngcairo noenhanced size 1000,600\n"
      << "set output " << gnuplot_quoted(dir.external("first_window.png")) << "\nset logscale y\n"
      << "set xlabel 'iteration'\nset ylabel 'step norm (max)'\nplot ";
    for (size_t i = 0; i < traced.size(); ++i) {
      long o = 0;  // the traced observer's index, for its style
      while (o < observers && r.metrics[static_cast<size_t>(o)].name != traced[i]) ++o;
      g << "'first_window.dat' index " << i << " using 2:3 with linespoints"
        << observer_style(o < observers ? o : 0) << " title " << gnuplot_quoted(traced[i])
        << (i + 1 < traced.size() ? ", " : "\n");
    }
  }
  return g.str();
}

}  // namespace

std::vector<std::string> write_run_files(OutputDirectory& dir, const Scenario& s,
                                         const Measurements& data, const RunResult& r,
                                         std::chrono::milliseconds plot_timeout,
                                         std::vector<std::string>& warnings, std::ostream& err) {
  std::vector<ColumnRef> refs;
  std::string header;
  {
    const ColumnTable table = run_table(data, r, false, refs, header);
    OutputDirectory::Writer csv = dir.open("trajectories.csv");
    write_csv_rows(csv.stream(), header, table);
    csv.commit();
  }
  {
    const ColumnTable table = run_table(data, r, true, refs, header);
    OutputDirectory::Writer csv = dir.open("plot_data.csv");
    write_plot_rows(csv.stream(), header, table);
    csv.commit();
  }
  std::vector<std::string> traced;
  dir.write("first_window.dat", first_window_csv(r, &traced));
  dir.write("scenario.json", to_json(s).dump(2) + "\n");
  if (!have_gnuplot()) {
    err << "nlobs: gnuplot not found: no PNG plots (apt-get install gnuplot-nox)\n";
    return {};
  }
  // Best-effort: the data files above are complete whatever gnuplot does.
  const std::string failure =
      run_gnuplot_script(dir, "plots.gp", plot_script(dir, data, r, traced), plot_timeout);
  if (failure.empty()) return dir.commit_external();
  dir.discard_external();
  warnings.push_back("no PNG plots: " + failure);
  err << "nlobs: warning: " << warnings.back() << '\n';
  return {};
}

void write_sweep_files(OutputDirectory& dir, const std::string& csv, const std::string& dat,
                       const std::string& plot_commands, std::chrono::milliseconds plot_timeout,
                       std::ostream& out, std::ostream& err) {
  dir.write("sweep.dat", dat);
  std::string plotted;
  if (have_gnuplot()) {
    const std::string script = "set terminal pngcairo noenhanced size 1000,800\nset output " +
                               gnuplot_quoted(dir.external("sweep.png")) + "\n" + plot_commands;
    const std::string failure = run_gnuplot_script(dir, "sweep.gp", script, plot_timeout);
    if (failure.empty()) {
      dir.commit_external();
      plotted = ", sweep.png";
    } else {
      dir.discard_external();
      err << "nlobs: warning: no sweep.png: " << failure << '\n';
    }
  }
  dir.remove_stale_files();
  dir.write("sweep.csv", csv);  // last: the directory is complete
  out << "wrote " << (dir.path() / "sweep.csv").string() << ", sweep.dat" << plotted << '\n';
}

}  // namespace nlobs::cli
