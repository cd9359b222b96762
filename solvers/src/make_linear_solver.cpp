#include "nlobs/solvers/linear/make_linear_solver.hpp"

#include <algorithm>
#include <limits>

#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/linear/band_lu.hpp"
#include "nlobs/solvers/linear/bicgstab.hpp"
#include "nlobs/solvers/linear/boomeramg.hpp"
#include "nlobs/solvers/linear/dense_lu.hpp"
#include "nlobs/solvers/linear/gmres.hpp"
#include "nlobs/solvers/linear/klu.hpp"
#include "nlobs/solvers/linear/preconditioners.hpp"
#include "nlobs/solvers/linear/sparse_lu.hpp"
#include "nlobs/solvers/linear/umfpack.hpp"
#include "nlobs/solvers/sparse/pattern_bandwidths.hpp"
#include "nlobs/solvers/sparse/sparsity_pattern.hpp"

namespace nlobs {
namespace {

constexpr int kIntMax = std::numeric_limits<int>::max();

const std::vector<EngineOptionInfo>& preconditioner_options() {
  static const std::vector<EngineOptionInfo> options = {
      {"preconditioner",
       "none (default), jacobi, ilu0, ilut or boomeramg (hypre's algebraic multigrid); right "
       "preconditioning"},
      {"drop_tolerance", "ilut: drop entries below this x the row norm, in (0, 1), default 1e-4"},
      {"fill_factor", "ilut: at most this x J's entries per row, >= 1, default 10"},
      {"strong_threshold", "boomeramg: strength of connection, in (0, 1), default 0.25"},
      {"cycles", "boomeramg: V-cycles per application, 1..100, default 1"}};
  return options;
}

std::unique_ptr<LinearPreconditioner> read_preconditioner(EngineSpecReader& reader) {
  const std::string kind = reader.text("preconditioner").value_or("none");
  // Options of one preconditioner given with another are refused, naming both.
  const auto belong_to = [&kind](const char* owner, bool given, const char* keys) {
    if (given && kind != owner) {
      throw InvalidInput(std::string("linear solver options ") + keys +
                         " belong to preconditioner=" + owner + ", not " + kind);
    }
  };
  IlutOptions ilut;
  const auto drop = reader.number("drop_tolerance");
  const auto fill = reader.integer("fill_factor", 1, kIntMax);
  belong_to("ilut", drop || fill, "drop_tolerance and fill_factor");
  if (drop) ilut.drop_tolerance = *drop;
  if (fill) ilut.fill_factor = *fill;
  BoomerAmgOptions amg;
  const auto threshold = reader.number("strong_threshold");
  const auto cycles = reader.integer("cycles", 1, 100);
  belong_to("boomeramg", threshold || cycles, "strong_threshold and cycles");
  if (threshold) amg.strong_threshold = *threshold;
  if (cycles) amg.cycles = *cycles;
  if (kind == "none") return nullptr;
  if (kind == "jacobi") return std::make_unique<JacobiPreconditioner>();
  if (kind == "ilu0") return std::make_unique<Ilu0Preconditioner>();
  if (kind == "ilut") return std::make_unique<IlutPreconditioner>(ilut);
  if (kind == "boomeramg") return std::make_unique<BoomerAmgPreconditioner>(amg);
  throw InvalidInput("linear solver preconditioner '" + kind +
                     "' is unknown; valid: none, jacobi, ilu0, ilut, boomeramg");
}

std::vector<EngineOptionInfo> with_preconditioner(std::vector<EngineOptionInfo> options) {
  const auto& more = preconditioner_options();
  options.insert(options.end(), more.begin(), more.end());
  return options;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> linear_solver_names() {
  return {
      {"dense-lu", "LU with partial pivoting of J made dense: O(n^2) memory, O(n^3) work"},
      {"band-lu", "band LU with partial pivoting (LAPACK dgbtf2): widths from J or lower=,upper="},
      {"sparse-lu", "Eigen's supernodal SparseLU, COLAMD ordering"},
      {"klu", "SuiteSparse KLU (BTF + AMD), refactoring with the last pivot order"},
      {"umfpack", "SuiteSparse UMFPACK, multifrontal (BLAS 3); ordering=amd (default) or metis"},
      {"gmres", "restarted GMRES(m), right-preconditioned"},
      {"bicgstab", "BiCGSTAB, right-preconditioned"}};
}

std::unique_ptr<LinearSolver> make_linear_solver(std::string_view text) {
  const EngineSpec spec = parse_engine_spec(text);
  if (spec.name == "dense-lu" || spec.name == "sparse-lu" || spec.name == "klu") {
    EngineSpecReader reader(spec, {});
    reader.finish();
    if (spec.name == "dense-lu") return std::make_unique<DenseLuSolver>();
    if (spec.name == "sparse-lu") return std::make_unique<SparseLuSolver>();
    return std::make_unique<KluSolver>();
  }
  if (spec.name == "umfpack") {
    EngineSpecReader reader(spec, {{"ordering", "amd (default) or metis (nested dissection)"}});
    const std::string ordering = reader.text("ordering").value_or("amd");
    reader.finish();
    if (ordering != "amd" && ordering != "metis") {
      throw InvalidInput("linear solver umfpack: ordering '" + ordering +
                         "' is unknown; valid: amd, metis");
    }
    return std::make_unique<UmfpackSolver>(ordering == "metis" ? UmfpackOrdering::kMetis
                                                               : UmfpackOrdering::kAmd);
  }
  if (spec.name == "band-lu") {
    EngineSpecReader reader(spec, {{"lower", "lower bandwidth, >= 0 (with upper; default: J's)"},
                                   {"upper", "upper bandwidth, >= 0 (with lower; default: J's)"}});
    const auto lower = reader.integer("lower", 0, kIntMax);
    const auto upper = reader.integer("upper", 0, kIntMax);
    reader.finish();
    if (lower.has_value() != upper.has_value()) {
      throw InvalidInput("linear solver spec '" + spec.text +
                         "': give both lower and upper, or neither");
    }
    if (lower) return std::make_unique<BandLuSolver>(*lower, *upper);
    return std::make_unique<BandLuSolver>();
  }
  if (spec.name == "gmres") {
    EngineSpecReader reader(
        spec, with_preconditioner({{"restart", "Krylov vectors per cycle, >= 1, default 30"},
                                   {"max_iterations", "over all cycles, >= 1, default 300"}}));
    GmresOptions options;
    if (const auto v = reader.integer("restart", 1, 100000)) options.restart = *v;
    if (const auto v = reader.integer("max_iterations", 1, kIntMax)) options.max_iterations = *v;
    auto preconditioner = read_preconditioner(reader);
    reader.finish();
    return std::make_unique<GmresSolver>(options, std::move(preconditioner));
  }
  if (spec.name == "bicgstab") {
    EngineSpecReader reader(spec, with_preconditioner({{"max_iterations", ">= 1, default 300"}}));
    BicgstabOptions options;
    if (const auto v = reader.integer("max_iterations", 1, kIntMax)) options.max_iterations = *v;
    auto preconditioner = read_preconditioner(reader);
    reader.finish();
    return std::make_unique<BicgstabSolver>(options, std::move(preconditioner));
  }
  std::string valid;
  for (const auto& [name, description] : linear_solver_names()) {
    valid += (valid.empty() ? "" : ", ") + name;
  }
  throw InvalidInput("linear solver '" + spec.name + "' is unknown; valid: " + valid);
}

std::string choose_linear_solver(const std::string& requested, const SparsityPattern& pattern,
                                 Index n) {
  if (pattern.rows != n || pattern.cols != n) {
    throw InvalidInput("the sparse Jacobian's pattern is " + std::to_string(pattern.rows) + "x" +
                       std::to_string(pattern.cols) + ", the problem has " + std::to_string(n) +
                       " unknowns");
  }
  if (requested != "auto") return requested;
  const PatternBandwidths band = pattern_bandwidths(pattern);
  if (std::max(band.lower, band.upper) <= kAutoBandWidth) return "band-lu";
  return n >= kAutoMultifrontalSize ? "umfpack" : "klu";
}

}  // namespace nlobs
