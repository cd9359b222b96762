#include "nlobs/registry/problem_sets.hpp"

#include <cmath>
#include <limits>
#include <new>
#include <set>
#include <sstream>

#include "nlobs/common/printable.hpp"
#include "nlobs/common/registry_name.hpp"
#include "problem_sets/builtin_problem_sets.hpp"

namespace nlobs {
namespace {

std::string shape(Index n) {
  return std::to_string(n);
}

[[noreturn]] void fail(std::string_view where, const TestProblem& p, const std::string& what) {
  std::ostringstream os;
  os << where << ": problem '" << printable(p.name, 60) << "' (n = " << p.residual.size()
     << "): " << what;
  throw InvalidInput(os.str());
}

}  // namespace

void validate_test_problem(const TestProblem& p, std::string_view where,
                           double solution_threshold) {
  const Index n = p.residual.size();
  if (!is_registry_name(p.name)) {
    throw InvalidInput(printable(where) + ": problem name '" + printable(p.name, 60) + "' " +
                       registry_name_problem(p.name) + " (" + std::string(kRegistryNameRule) + ")");
  }
  if (n <= 0) fail(where, p, "it has no unknowns: n must be at least 1");
  if (n > kMaxSparseProblemDimension) {
    fail(where, p,
         "n = " + shape(n) + " is above the limit of " + shape(kMaxSparseProblemDimension) +
             " unknowns");
  }
  if (p.residual.residual_size() != n) {
    fail(where, p,
         "F has " + shape(p.residual.residual_size()) + " components for " + shape(n) +
             " unknowns; a problem set holds square systems");
  }
  if (!p.residual.has_jacobian()) {
    fail(where, p,
         "F has no Jacobian (build it with_autodiff or with_jacobian): Newton and the "
         "reference solvers need one");
  }
  if (p.fixed_point && p.fixed_point->size() != n) {
    fail(where, p, "the fixed-point map G has size " + shape(p.fixed_point->size()));
  }
  if (p.starts.empty()) fail(where, p, "no start");
  auto check_bound = [&](const Eigen::VectorXd& b, const char* side) {
    if (b.size() != 0 && b.size() != n) {
      fail(where, p, std::string(side) + " has size " + shape(b.size()));
    }
    for (Index i = 0; i < b.size(); ++i) {
      if (std::isnan(b[i])) fail(where, p, std::string(side) + "[" + shape(i) + "] is NaN");
    }
  };
  check_bound(p.lower, "lower");
  check_bound(p.upper, "upper");
  if (p.lower.size() == n && p.upper.size() == n) {
    for (Index i = 0; i < n; ++i) {
      if (!(p.lower[i] <= p.upper[i])) {
        std::ostringstream os;
        os << "lower[" << i << "] = " << p.lower[i] << " > upper[" << i << "] = " << p.upper[i];
        fail(where, p, os.str());
      }
    }
  }
  auto check_strict = [&](const StrictBounds& strict, const Eigen::VectorXd& b, const char* name,
                          const char* side) {
    if (strict.size() != 0 && strict.size() != b.size()) {
      fail(where, p,
           std::string(name) + " has " + shape(strict.size()) + " flags, " + side + " " +
               shape(b.size()) + " bounds (one flag per bound)");
    }
  };
  check_strict(p.strict_lower, p.lower, "strict_lower", "lower");
  check_strict(p.strict_upper, p.upper, "strict_upper", "upper");
  if (p.lower.size() == n && p.upper.size() == n) {
    for (Index i = 0; i < n; ++i) {
      const bool strict = (p.strict_lower.size() == n && p.strict_lower[i]) ||
                          (p.strict_upper.size() == n && p.strict_upper[i]);
      if (strict && p.lower[i] == p.upper[i]) {
        std::ostringstream os;
        os << "lower[" << i << "] = upper[" << i << "] = " << p.lower[i]
           << " with a strict side: no x satisfies it";
        fail(where, p, os.str());
      }
    }
  }
  auto check_scale = [&](const Eigen::VectorXd& d, const char* name) {
    if (d.size() != 0 && d.size() != n)
      fail(where, p, std::string(name) + " has size " + shape(d.size()));
    for (Index i = 0; i < d.size(); ++i) {
      if (!(d[i] > 0.0) || !std::isfinite(d[i])) {
        std::ostringstream os;
        os << name << "[" << i << "] = " << d[i] << " is not finite and > 0";
        fail(where, p, os.str());
      }
    }
  };
  check_scale(p.u_scale, "u_scale");
  check_scale(p.f_scale, "f_scale");
  std::set<std::string> labels;
  for (const ProblemStart& s : p.starts) {
    const std::string which = "start '" + printable(s.label, 60) + "'";
    if (s.label.empty()) fail(where, p, "a start without a label");
    if (!labels.insert(s.label).second) fail(where, p, which + " is listed twice");
    if (s.x.size() != n) fail(where, p, which + " has size " + shape(s.x.size()));
    if (!s.x.allFinite()) fail(where, p, which + " is not finite");
    if (!std::isfinite(s.scale)) fail(where, p, which + ": its scale is not finite");
    if (const auto i = p.first_outside_bounds(s.x)) {
      fail(where, p, which + ": x[" + shape(*i) + "] is outside the bounds");
    }
  }
  if (n > kMaxProblemDimension) {  // the dense solvers could not hold it: F must be sparse
    std::string why;
    try {
      if (!p.residual.sparse_jacobian(p.starts.front().x)) why = p.residual.sparse_jacobian_note();
    } catch (...) {
      why = "detecting it threw: " + current_exception_text();
    }
    if (!why.empty()) {
      fail(where, p,
           "n = " + shape(n) + " is above the limit of " + shape(kMaxProblemDimension) +
               " unknowns for a dense Jacobian, and F has no sparse one (declare it with "
               "sparse_autodiff_problem, or build F with_autodiff for nlobs to detect it; "
               "detection: " +
               printable(why, 200) + ")");
    }
  }
  for (std::size_t k = 0; k < p.solutions.size(); ++k) {
    const std::string which = "known solution " + std::to_string(k);
    if (p.solutions[k].size() != n) {
      fail(where, p, which + " has size " + shape(p.solutions[k].size()));
    }
    if (!p.solutions[k].allFinite()) fail(where, p, which + " is not finite");
    if (const auto i = p.first_outside_bounds(p.solutions[k])) {
      fail(where, p, which + ": x[" + shape(*i) + "] is outside the bounds");
    }
    Eigen::VectorXd f(n);
    try {
      p.residual.evaluate(p.solutions[k], f);
    } catch (...) {
      fail(where, p, which + ": F throws there: " + current_exception_text());
    }
    const double norm = f.size() == n ? p.scaled_norm(f) : std::numeric_limits<double>::infinity();
    if (!(norm <= solution_threshold)) {
      std::ostringstream os;
      os << which << " is not a root: |" << (p.f_scale.size() ? "D_f " : "") << "F(x*)|2 = " << norm
         << " > " << solution_threshold << " (the set's threshold)";
      fail(where, p, os.str());
    }
  }
}

NamedRegistry<ProblemSetEntry>& problem_set_registry() {
  static NamedRegistry<ProblemSetEntry> registry = [] {
    NamedRegistry<ProblemSetEntry> r("problem set");
    detail::add_builtin_problem_sets(r);
    return r;
  }();
  return registry;
}

namespace {

// The set's problems as its functions build them, not yet validated.
std::vector<TestProblem> unchecked_problems(const ProblemSetEntry& set, std::optional<Index> n) {
  const std::string where = "problem set '" + set.name + "'";
  if (!set.problems) throw InvalidInput(where + ": no function builds its problems");
  if (!(set.solved_threshold > 0.0) || !std::isfinite(set.solved_threshold)) {
    throw InvalidInput(where + ": solved_threshold must be finite and > 0");
  }
  if (n && !set.problems_of_size) {
    throw InvalidInput(where + " has fixed sizes (':n=K' after a problem's name selects one)");
  }
  if (n && (*n < 1 || *n > kMaxSparseProblemDimension)) {
    throw InvalidInput(where + ": n = " + std::to_string(*n) + " is not in 1 .. " +
                       std::to_string(kMaxSparseProblemDimension));
  }
  std::vector<TestProblem> problems;
  try {  // a user's function (a plugin's): anything it throws is named by the set
    problems = n ? set.problems_of_size(*n) : set.problems();
  } catch (const std::bad_alloc&) {
    throw InvalidInput(where + ": building its problems ran out of memory (std::bad_alloc)");
  } catch (...) {
    throw InvalidInput(where + ": building its problems threw: " + current_exception_text());
  }
  if (problems.empty()) throw InvalidInput(where + ": it has no problems");
  return problems;
}

// Each problem valid, (name, n) unique. Validation costs (detection at 10⁶ unknowns takes
// seconds): a selection validates only what it selected.
void validate_problems(const ProblemSetEntry& set, const std::vector<TestProblem>& problems) {
  const std::string where = "problem set '" + set.name + "'";
  std::set<std::pair<std::string, Index>> seen;
  for (const TestProblem& p : problems) {
    validate_test_problem(p, where, set.solved_threshold);
    if (!seen.insert({p.name, p.size()}).second) {
      fail(where, p, "listed twice (a name is unique per size)");
    }
  }
}

}  // namespace

std::vector<TestProblem> build_problem_set(const ProblemSetEntry& set, std::optional<Index> n) {
  std::vector<TestProblem> problems = unchecked_problems(set, n);
  validate_problems(set, problems);
  return problems;
}

namespace {

// Splits "NAME:n=K" into NAME and K (none without a colon); InvalidInput for another suffix.
std::optional<Index> take_size(std::string& name, const std::string& selector) {
  const std::size_t colon = name.find(':');
  if (colon == std::string::npos) return std::nullopt;
  const std::string size_text = name.substr(colon + 1);
  name.resize(colon);
  const bool digits = size_text.size() > 2 && size_text.size() <= 11 &&
                      size_text.compare(0, 2, "n=") == 0 &&
                      size_text.find_first_not_of("0123456789", 2) == std::string::npos;
  if (!digits) {
    throw InvalidInput("problem '" + selector.substr(0, 60) +
                       "': after the name, ':n=K' with K a positive integer selects a size");
  }
  return std::stol(size_text.substr(2));
}

}  // namespace

ProblemSelection select_problems(std::string_view selector,
                                 const NamedRegistry<ProblemSetEntry>& registry) {
  const std::string text(selector);
  const std::size_t slash = text.find('/');
  std::string set_name = text.substr(0, slash);
  std::string name = slash == std::string::npos ? std::string() : text.substr(slash + 1);
  std::optional<Index> n = take_size(slash == std::string::npos ? set_name : name, text);
  const ProblemSetEntry* set = registry.find(set_name);
  if (!set) {
    throw InvalidInput("unknown problem set '" + set_name.substr(0, 60) +
                       "'; valid problem sets: " + registry.valid_list());
  }
  // A set of run-time size builds its problems at n itself: each at the size nearest n it has.
  const bool sized = n && set->problems_of_size;
  ProblemSelection out{
      set, unchecked_problems(*set, sized || slash == std::string::npos ? n : std::nullopt)};
  if (slash == std::string::npos) {
    validate_problems(*set, out.problems);
    return out;
  }

  std::vector<TestProblem> chosen;
  std::string names;
  for (TestProblem& p : out.problems) {
    names += (names.empty() ? "" : ", ") + p.name + ":n=" + std::to_string(p.size());
    if (p.name == name && (!n || sized || *n == p.size())) chosen.push_back(std::move(p));
  }
  if (chosen.empty()) {
    throw InvalidInput("problem set '" + set->name + "' has no problem '" +
                       text.substr(slash + 1, 60) + "'; its problems: " + names);
  }
  validate_problems(*set, chosen);
  out.problems = std::move(chosen);
  return out;
}

}  // namespace nlobs
