#include "suite_mgh.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <ostream>
#include <string>

namespace nlobs::cli {

void print_suite_tables(const std::vector<reference::SuiteRow>& rows, std::ostream& out) {
  char line[256];
  std::string current;
  std::vector<std::string> order;
  std::map<std::string, int> solved, pairs;
  for (const auto& r : rows) {
    char key[128];
    std::snprintf(key, sizeof key, "%s n=%d x%g", r.problem.c_str(), r.n, r.start_scale);
    if (current != key) {
      current = key;
      std::snprintf(line, sizeof line, "\n%s (start x %g)\n  %-22s %-7s %-28s %10s %8s %8s %12s\n",
                    (r.problem + " n=" + std::to_string(r.n)).c_str(), r.start_scale, "solver",
                    "solved", "status", "|F|2", "F evals", "J evals", "time [us]");
      out << line;
    }
    std::snprintf(line, sizeof line, "  %-22s %-7s %-28s %10.2e %8ld %8ld %12.1f\n",
                  r.solver.c_str(), r.solved ? "yes" : "no", r.status.substr(0, 28).c_str(),
                  r.residual, r.f_evals, r.j_evals, r.ns / 1e3);
    out << line;
    if (!pairs.count(r.solver)) order.push_back(r.solver);
    ++pairs[r.solver];
    solved[r.solver] += r.solved;
  }
  out << "\nsolved (|F|2 <= 1e-8 at the returned point), per solver:\n";
  for (const auto& s : order) {
    std::snprintf(line, sizeof line, "  %-22s %3d / %d\n", s.c_str(), solved[s], pairs[s]);
    out << line;
  }
}

nlohmann::json suite_to_json(const std::vector<reference::SuiteRow>& rows) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& r : rows) {
    a.push_back({{"problem", r.problem},
                 {"n", r.n},
                 {"start_scale", r.start_scale},
                 {"solver", r.solver},
                 {"solved", r.solved},
                 {"residual",
                  std::isfinite(r.residual) ? nlohmann::json(r.residual) : nlohmann::json(nullptr)},
                 {"f_evals", r.f_evals},
                 {"j_evals", r.j_evals},
                 {"ns", r.ns},
                 {"status", r.status}});
  }
  return a;
}

}  // namespace nlobs::cli
