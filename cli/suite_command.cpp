#include "suite_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <ostream>
#include <stdexcept>

#include "nlobs/common/printable.hpp"
#include "nlobs/reference/petsc_solver.hpp"
#include "nlobs/reference/problem_suite.hpp"
#include "nlobs/registry/problem_sets.hpp"
#include "nlobs/solvers/engine.hpp"
#include "output_file.hpp"
#include "suite_report.hpp"

namespace nlobs::cli {
namespace {

// "nlobs solve --starts: no selected problem (mgh/rosenbrock) has a start 'x5'; their starts:
// x1, x10, x100": the flag, the label and the labels there are, in the order the problems list
// them.
std::string unknown_start_message(const std::string& command,
                                  const std::vector<std::string>& selectors,
                                  const std::vector<ProblemSelection>& selections,
                                  const std::string& wanted) {
  std::string selected, valid;
  for (const std::string& selector : selectors) {
    selected += (selected.empty() ? "" : ", ") + selector;
  }
  std::vector<std::string> labels;
  for (const ProblemSelection& s : selections) {
    for (const TestProblem& p : s.problems) {
      for (const ProblemStart& st : p.starts) {
        if (std::find(labels.begin(), labels.end(), st.label) == labels.end()) {
          labels.push_back(st.label);
        }
      }
    }
  }
  for (const std::string& label : labels) valid += (valid.empty() ? "" : ", ") + label;
  return "nlobs " + command + " --starts: no selected problem (" + nlobs::printable(selected, 200) +
         ") has a start '" + nlobs::printable(wanted, 60) +
         "'; their starts: " + (valid.empty() ? "none" : nlobs::printable(valid, 400));
}

}  // namespace

void run_problem_suite(const std::vector<std::string>& selectors, const SuiteArguments& args,
                       const std::string& command, std::ostream& out, std::ostream& err) {
  if (selectors.empty()) {
    throw std::invalid_argument("nlobs " + command +
                                ": name a problem set or problem (nlobs list problems)");
  }
  if (args.json && args.csv == "-") {
    throw std::invalid_argument("nlobs " + command +
                                ": --json and --csv - both print to stdout; give --csv a file");
  }
  reference::SuiteOptions options;
  options.solved_threshold = args.threshold;
  options.evaluations_per_dimension = args.evaluations_per_dimension;
  options.time_limit_s = args.time_limit_s;
  options.starts =
      args.starts.empty() ? std::vector<std::string>() : reference::split_spec_list(args.starts);
  if (args.monitor) {
    options.monitor = [&err](const std::string& solver, const std::string& problem_start,
                             const IterationRecord& r) {
      char line[96];
      std::snprintf(line, sizeof line, "  %6d  |step| %.3e  |F| %.3e\n", r.iteration, r.step_norm,
                    r.residual_norm);
      err << nlobs::printable(solver, 60) << "  " << nlobs::printable(problem_start, 80) << line;
    };
  }
  // --solvers, or none: each set's own default list (ProblemSetEntry::default_solvers), else the
  // suite's.
  std::vector<std::string> solvers;
  // A solver or problem named twice runs once (a second row would only repeat the first), said
  // on `err`.
  for (std::string& spec : reference::split_spec_list(args.solvers)) {
    if (std::find(solvers.begin(), solvers.end(), spec) != solvers.end()) {
      err << "nlobs " << command << ": solver '" << nlobs::printable(spec, 60)
          << "' is listed more than once; it runs once\n";
    } else {
      solvers.push_back(std::move(spec));
    }
  }
  if (!args.solvers.empty() && solvers.empty()) {
    throw std::invalid_argument("nlobs " + command + " --solvers: no solver listed");
  }
  // Every selection is built and checked before the first solve.
  std::vector<ProblemSelection> selections;
  double threshold = std::numeric_limits<double>::quiet_NaN();
  for (const std::string& selector : selectors) {
    if (command == "suite" && selector.find('/') != std::string::npos) {
      throw std::invalid_argument(
          "nlobs suite takes a problem set ('" + nlobs::printable(selector, 60) +
          "' names a problem: nlobs solve " + nlobs::printable(selector, 60) + ")");
    }
    ProblemSelection selection = select_problems(selector, problem_set_registry());
    std::erase_if(selection.problems, [&](const TestProblem& p) {
      const bool seen = std::any_of(selections.begin(), selections.end(), [&](const auto& s) {
        return s.set == selection.set &&
               std::any_of(s.problems.begin(), s.problems.end(), [&](const TestProblem& q) {
                 return q.name == p.name && q.size() == p.size();
               });
      });
      if (seen) {
        err << "nlobs " << command << ": " << nlobs::printable(selection.set->name, 60) << '/'
            << nlobs::printable(p.name, 60) << ":n=" << p.size()
            << " is selected more than once; it runs once\n";
      }
      return seen;
    });
    selections.push_back(std::move(selection));
    const double t = reference::suite_threshold(*selections.back().set, options);
    threshold =
        selections.size() == 1 || t == threshold ? t : std::numeric_limits<double>::quiet_NaN();
  }
  // --starts is checked against every selected problem before the first solve (run_suite checks
  // one set at a time, so a label only a later selector's problems have was refused after the
  // earlier ones had run, and a label another problem of the set has was said to be in none).
  std::vector<std::vector<std::string>> starts_of_selection(selections.size());
  for (const std::string& wanted : options.starts) {
    bool found = false;
    for (std::size_t i = 0; i < selections.size(); ++i) {
      const bool has = std::any_of(
          selections[i].problems.begin(), selections[i].problems.end(), [&](const TestProblem& p) {
            return std::any_of(p.starts.begin(), p.starts.end(),
                               [&](const ProblemStart& st) { return st.label == wanted; });
          });
      auto& labels = starts_of_selection[i];
      if (has && std::find(labels.begin(), labels.end(), wanted) == labels.end()) {
        labels.push_back(wanted);
      }
      found = found || has;
    }
    if (!found)
      throw std::invalid_argument(unknown_start_message(command, selectors, selections, wanted));
  }
  // The CSV's file is opened (its temporary made, or the FIFO or device opened) before the first
  // solve: a target that cannot be written is refused at once, not after a long run, and the
  // file there now is replaced only when the rows are complete.
  std::optional<OutputFile> csv_file;
  if (!args.csv.empty() && args.csv != "-") csv_file.emplace(args.csv);
  int total = 0, before = 0;
  for (const ProblemSelection& s : selections) {
    total += reference::count_suite_pairs(s.problems, options);
  }
  const std::vector<std::string> default_solvers = reference::default_suite_solvers();
  std::vector<reference::SuiteRow> rows;
  using Clock = std::chrono::steady_clock;
  const Clock::time_point started = Clock::now();
  Clock::time_point last_line = started;
  const auto interval = std::chrono::duration<double>(args.progress_interval_s);
  for (std::size_t i = 0; i < selections.size(); ++i) {
    const ProblemSelection& s = selections[i];
    reference::SuiteOptions o = options;
    // Only the labels this selection's problems have (run_suite refuses the others); none of
    // them: nothing of it runs (an empty list would mean every start).
    if (!options.starts.empty()) {
      if (starts_of_selection[i].empty()) continue;
      o.starts = starts_of_selection[i];
    }
    if (args.monitor) {
      // The iterations' lines stand alone: no progress line between them.
    } else if (args.progress == SuiteArguments::Progress::kTerminal) {
      o.progress = [&, before](int done, int) {
        err << "\rnlobs " << command << ": " << before + done << "/" << total
            << " (problem, start) pairs" << std::flush;
      };
    } else if (args.progress == SuiteArguments::Progress::kLines) {
      o.progress = [&, before](int done, int) {
        const Clock::time_point now = Clock::now();
        if (now - last_line < interval) return;
        last_line = now;
        err << "nlobs " << command << ": " << before + done << "/" << total
            << " (problem, start) pairs, "
            << static_cast<long>(std::chrono::duration<double>(now - started).count()) << " s\n"
            << std::flush;
      };
    }
    std::vector<std::string> set_solvers = !solvers.empty() ? solvers
                                           : s.set->default_solvers.empty()
                                               ? default_solvers
                                               : s.set->default_solvers;
    // A set's own list names PETSc (large); a build without it leaves those rows out, saying so.
    if (solvers.empty() && !reference::petsc_available()) {
      std::erase_if(set_solvers, [&err, &command](const std::string& name) {
        if (!reference::PetscSnesSolver::is_name(name)) return false;
        err << "nlobs " << command << ": " << name
            << " left out: this nlobs was built without PETSc\n";
        return true;
      });
    }
    const auto part = reference::run_suite(*s.set, s.problems, set_solvers, o);
    before += reference::count_suite_pairs(s.problems, options);
    rows.insert(rows.end(), part.begin(), part.end());
  }
  if (args.progress == SuiteArguments::Progress::kTerminal) err << '\n';
  if (csv_file) {
    csv_file->stream() << suite_to_csv(rows);
    csv_file->commit();
  } else if (args.csv == "-") {
    out << suite_to_csv(rows);
  }
  if (args.json) {
    out << suite_to_json(rows).dump(2) << '\n';
  } else if (args.csv != "-") {
    print_suite_tables(rows, threshold, out, args.show_x);
  }
}

}  // namespace nlobs::cli
