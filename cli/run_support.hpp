#pragma once
// What `nlobs run`'s parts share (run_command.cpp, modulating_report.cpp).
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nlobs/observers/simulation.hpp"

namespace nlobs::cli {

// Writes through a temporary name and renames at the end: nothing half-written looks complete.
void write_atomically(const std::filesystem::path& path, const std::string& content);
nlohmann::json number_or_null(double v);
std::string fmt(double v, const char* f = "%.3e");  // "-" for non-finite values
bool have_gnuplot();
// Observers in other coordinates publish their estimate there as extras zhat1… (high gain) or
// eta1… (modulating functions): with the truth known, the error in those coordinates becomes
// the extra "z_error" or "eta_error" (and, for eta, the true norm "eta_norm").
void add_coordinate_errors(const Measurements& data,
                           const std::vector<std::unique_ptr<Observer>>& observers, RunResult& r);

}  // namespace nlobs::cli
