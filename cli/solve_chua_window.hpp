#pragma once
// `nlobs solve chua-window`: the modified-Chua window problem ([MGFF23]) solved by each
// listed engine and, in the same run, by KINSOL's fixed-point, Anderson and Newton strategies.
#include <Eigen/Core>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace nlobs::cli {

struct SolveRow {
  std::string engine;
  std::string status;
  long iterations = 0;
  long evaluations = 0;
  Eigen::Vector3d solution = Eigen::Vector3d::Zero();
  double error = 0.0;  // ‖x − x_true‖∞
  double ns_per_solve = 0.0;
  // Status "engine_threw": what the engine threw (printable); the run goes on with the next.
  std::string message;
};

// Our engines' names, in table order.
const std::vector<std::string>& engine_names();
// KINSOL rows, in table order.
const std::vector<std::string>& reference_names();

// Throws std::invalid_argument for an unknown engine name (the message lists valid ones) or a
// tolerance that is not finite and > 0.
std::vector<SolveRow> solve_chua_window(const std::vector<std::string>& engines, double tolerance,
                                        bool with_reference);

void print_table(const std::vector<SolveRow>& rows, double tolerance, std::ostream& out);
nlohmann::json to_json(const std::vector<SolveRow>& rows);

}  // namespace nlobs::cli
