#include "suite_report.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "nlobs/common/printable.hpp"
#include "run_support.hpp"

namespace nlobs::cli {
namespace {

// printf into a string of whatever length it takes. A fixed line buffer cut long lines: a
// plugin's names, escaped by printable (a byte may become "\\xNN"), overran 400 bytes, and the
// cut split a UTF-8 sequence and dropped the line's end (found by fuzz_suite_report).
[[gnu::format(printf, 1, 2)]] std::string formatted(const char* format, ...) {
  va_list args, again;
  va_start(args, format);
  va_copy(again, args);
  const int size = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string text(size > 0 ? static_cast<std::size_t>(size) : 0U, '\0');
  if (size > 0) std::vsnprintf(text.data(), text.size() + 1, format, again);
  va_end(again);
  return text;
}

// 1e-08 as "1e-8": the threshold as a user types it.
std::string short_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  std::string s = text;
  for (const char* from : {"e-0", "e+0"}) {
    const std::size_t at = s.find(from);
    if (at != std::string::npos) s.erase(at + 2, 1);
  }
  return s;
}

std::string number_text(double v) {
  if (!std::isfinite(v)) return "";
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

// "[1, 2.5, nan, ... (12 more)]": the first components of an answer, 6 significant digits.
std::string answer_text(const Eigen::VectorXd& x, Index max_components) {
  std::ostringstream os;
  os.precision(6);
  os << '[';
  const Index shown = std::min(x.size(), max_components);
  for (Index i = 0; i < shown; ++i) {
    os << (i ? ", " : "");
    if (std::isnan(x[i])) {
      os << "nan";  // not the C library's "-nan" for a NaN with its sign bit set
    } else {
      os << x[i];
    }
  }
  if (shown < x.size()) os << ", ... (" << x.size() - shown << " more)";
  os << ']';
  return os.str();
}

bool has_scaled_residual(const reference::SuiteRow& r) {
  return r.scaled_residual != r.residual &&
         !(std::isnan(r.scaled_residual) && std::isnan(r.residual));
}

}  // namespace

std::string answer_field(const Eigen::VectorXd& x) {
  std::string out;
  char text[32];
  for (Index i = 0; i < x.size(); ++i) {
    if (i) out += ' ';
    if (std::isnan(x[i])) {
      out += "nan";
    } else if (std::isinf(x[i])) {
      out += x[i] > 0 ? "inf" : "-inf";
    } else {
      std::snprintf(text, sizeof text, "%.17g", x[i]);
      out += text;
    }
  }
  return out;
}

void print_suite_tables(const std::vector<reference::SuiteRow>& rows, double threshold,
                        std::ostream& out, bool show_x) {
  std::string current;
  std::vector<std::string> order;
  std::map<std::string, int> solved, pairs;
  // Per solver: the most evaluations a run made after ‖F‖ last fell, and which run.
  std::map<std::string, std::pair<long, std::string>> idle;
  const bool any_error = std::any_of(
      rows.begin(), rows.end(), [](const reference::SuiteRow& r) { return !std::isnan(r.error); });
  const bool any_scaled = std::any_of(rows.begin(), rows.end(), has_scaled_residual);
  // Names, labels and statuses may come from a user's plugin: printed through printable (no
  // control character, no invalid UTF-8, bounded length).
  const auto shown = [](const std::string& text, std::size_t limit) {
    return printable(text, limit);
  };
  // The solver column fits the longest spec, within reason: 64 holds the large set's
  // "newton:linesearch=1,linear=gmres,preconditioner=boomeramg" whole (at 48 it and its ilu0
  // sibling printed alike).
  constexpr std::size_t kSolverWidth = 64;
  int width = 22;
  for (const auto& r : rows) {
    width = std::max(width, static_cast<int>(std::min(r.solver.size(), kSolverWidth)));
  }
  for (const auto& r : rows) {
    const std::string key = r.set + "/" + r.problem + " n=" + std::to_string(r.n) + " " + r.start;
    if (current != key) {
      current = key;
      // A scaled standard start ("x10") reads as before: "start x 10".
      const std::string scale = short_number(r.start_scale);
      std::string start = "start ";
      if (r.start.size() == scale.size() + 1 && r.start[0] == 'x' &&
          r.start.compare(1, std::string::npos, scale) == 0) {
        start += "x " + scale;
      } else {
        start += shown(r.start, 60);
      }
      out << formatted("\n%s n=%d (%s)\n  %-*s %-7s %-28s %10s %8s %8s %12s%s%s\n",
                       shown(r.problem, 80).c_str(), r.n, start.c_str(), width, "solver", "solved",
                       "status", "|F|2", "F evals", "J evals", "time [us]",
                       any_error ? "  |x-x*|inf" : "", any_scaled ? "   |D_f F|2" : "");
    }
    const std::string solver = shown(r.solver, kSolverWidth);
    out << formatted("  %-*s %-7s %-28s %10.2e %8ld %8ld %12.1f", width, solver.c_str(),
                     r.solved ? "yes" : "no", shown(r.status, 28).c_str(), r.residual, r.f_evals,
                     r.j_evals, r.ns / 1e3);
    if (any_error) {
      out << formatted(" %11s", fmt(r.error, "%.2e").c_str());
    }
    if (any_scaled) {
      out << formatted(" %11s", fmt(r.scaled_residual, "%.2e").c_str());
    }
    out << '\n';
    // A row without an answer, or stopped by the time limit, says why on the next line.
    if (!r.message.empty() && (r.status == "invalid_input" || r.status == "engine_threw" ||
                               r.status == "out_of_memory" || r.status == "time_limit")) {
      out << "    " << shown(r.message, 200) << '\n';
    }
    if (show_x && r.x.size() > 0) out << "    x = " << answer_text(r.x, 8) << '\n';
    if (!pairs.count(r.solver)) order.push_back(r.solver);
    ++pairs[r.solver];
    solved[r.solver] += r.solved;
    auto& worst = idle[r.solver];
    if (r.evals_past_progress > worst.first) {
      worst = {r.evals_past_progress, r.problem + " n=" + std::to_string(r.n) + " " + r.start};
    }
  }
  out << "\nsolved (" << (any_scaled ? "|D_f F|2" : "|F|2") << " <= "
      << (std::isnan(threshold) ? std::string("each set's threshold") : short_number(threshold))
      << " at the returned point), per solver:\n";
  for (const auto& s : order) {
    const auto& worst = idle[s];
    out << formatted("  %-*s %3d / %-4d idle %6ld%s%s%s\n", width, shown(s, kSolverWidth).c_str(),
                     solved[s], pairs[s], worst.first, worst.first > 0 ? " (" : "",
                     shown(worst.second, 100).c_str(), worst.first > 0 ? ")" : "");
  }
  out << "idle: the most F evaluations one run made after |F| last fell by 0.1 % (below 0.999 x "
         "its value at the fall before; that run; evals_past_progress in JSON and CSV)\n";
}

std::string valid_utf8(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      out += static_cast<char>(c);
      ++i;
      continue;
    }
    const std::size_t length = detail::utf8_sequence_length(text, i);
    if (length == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD
      ++i;
    } else {
      out.append(text.substr(i, length));
      i += length;
    }
  }
  return out;
}

nlohmann::json suite_to_json(const std::vector<reference::SuiteRow>& rows) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& r : rows) {
    a.push_back({{"set", valid_utf8(r.set)},
                 {"problem", valid_utf8(r.problem)},
                 {"n", r.n},
                 {"start", valid_utf8(r.start)},
                 {"start_scale", number_or_null(r.start_scale)},
                 {"solver", valid_utf8(r.solver)},
                 {"solved", r.solved},
                 {"residual", number_or_null(r.residual)},
                 {"error", number_or_null(r.error)},
                 {"f_evals", r.f_evals},
                 {"j_evals", r.j_evals},
                 {"ns", number_or_null(r.ns)},
                 {"status", valid_utf8(r.status)},
                 {"message", valid_utf8(r.message)},
                 {"scaled_residual", number_or_null(r.scaled_residual)},
                 {"x", nullptr},
                 {"evals_past_progress", r.evals_past_progress}});
    if (r.x.size() > 0) {
      nlohmann::json x = nlohmann::json::array();
      for (Index i = 0; i < r.x.size(); ++i) x.push_back(number_or_null(r.x[i]));
      a.back()["x"] = std::move(x);
    }
  }
  return a;
}

std::string suite_to_csv(const std::vector<reference::SuiteRow>& rows) {
  std::string out =
      "set,problem,n,start,start_scale,solver,solved,residual,error,f_evals,j_evals,ns,status,"
      "message,scaled_residual,x,evals_past_progress\n";
  for (const auto& r : rows) {
    out += csv_field(r.set) + ',' + csv_field(r.problem) + ',' + std::to_string(r.n) + ',' +
           csv_field(r.start) + ',' + number_text(r.start_scale) + ',' + csv_field(r.solver) + ',' +
           (r.solved ? "true" : "false") + ',' + number_text(r.residual) + ',' +
           number_text(r.error) + ',' + std::to_string(r.f_evals) + ',' +
           std::to_string(r.j_evals) + ',' + number_text(r.ns) + ',' + csv_field(r.status) + ',' +
           csv_field(r.message) + ',' + number_text(r.scaled_residual) + ',' + answer_field(r.x) +
           ',' + std::to_string(r.evals_past_progress) + '\n';
  }
  return out;
}

}  // namespace nlobs::cli
