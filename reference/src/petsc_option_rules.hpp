#pragma once
// The rules a PETSc option given to PetscSnesSolver obeys (petsc_solver.hpp), shared by the
// solver and the parser of petsc:TYPE:-key=value names. Private to nlobs::reference.
#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <string>

namespace nlobs::reference::petsc_rules {

inline bool lower_word(const std::string& s, std::size_t from) {
  if (from >= s.size()) return false;
  return std::all_of(s.begin() + static_cast<std::ptrdiff_t>(from), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

// The viewer options a user may give: each prints text to standard output (PETSc's ASCII viewer,
// its default for these). Any other viewer (a key with _view, _monitor or _converged_reason)
// could write a file (binary, hdf5), open a window (draw, the _lg monitors) or a socket: refused.
inline bool printing_viewer(const std::string& key) {
  static const char* const kViewers[] = {
      "-snes_monitor",      "-snes_monitor_short",        "-snes_converged_reason",
      "-snes_view",         "-snes_linesearch_monitor",   "-ksp_monitor",
      "-ksp_monitor_short", "-ksp_monitor_true_residual", "-ksp_converged_reason",
      "-ksp_view"};
  return std::find(std::begin(kViewers), std::end(kViewers), key) != std::end(kViewers);
}

inline bool names_a_viewer(const std::string& key) {
  return key.find("_view") != std::string::npos || key.find("_monitor") != std::string::npos ||
         key.find("_converged_reason") != std::string::npos;
}

// Keys of one SNES and its line search, KSP and PC; values without '/' or ':' (no path).
// Refused too: what would replace what the row's name says (-snes_type: petsc:TYPE names it) or
// bypass the counted Jacobian (-snes_fd, -snes_fd_color: PETSc's own differences, uncounted).
inline void validate_option(const std::string& key, const std::string& value) {
  static const char* const kFamilies[] = {"-snes_", "-ksp_", "-pc_"};
  bool family = false;
  for (const char* f : kFamilies) {
    const std::string prefix(f);
    if (key.compare(0, prefix.size(), prefix) == 0 && lower_word(key, prefix.size())) family = true;
  }
  if (!family || key.size() > 64) {
    throw std::invalid_argument("PETSc option '" + key +
                                "': a key is -snes_, -ksp_ or -pc_ followed by "
                                "lower-case letters, digits and '_' (at most 64 characters)");
  }
  const bool ok_value = value.size() <= 64 && std::all_of(value.begin(), value.end(), [](char c) {
                          return std::isalnum(static_cast<unsigned char>(c)) || c == '.' ||
                                 c == '_' || c == '+' || c == '-';
                        });
  if (!ok_value) {
    throw std::invalid_argument("PETSc option " + key + " = '" + value +
                                "': a value is letters, digits and ._+- (at most 64 characters)");
  }
  if (key == "-snes_type" || key == "-snes_fd" || key == "-snes_fd_color") {
    throw std::invalid_argument("PETSc option " + key +
                                ": not taken (the SNES type is the name's petsc:TYPE; the "
                                "Jacobian is PETSc's coloured differences, counted, or -snes_mf)");
  }
  if (names_a_viewer(key) && (!printing_viewer(key) || !(value.empty() || value == "ascii"))) {
    throw std::invalid_argument(
        "PETSc option " + key + (value.empty() ? "" : "=" + value) +
        ": the viewers taken print to standard output, without a value (or =ascii): "
        "-snes_monitor, -snes_monitor_short, -snes_converged_reason, -snes_view, "
        "-snes_linesearch_monitor, -ksp_monitor, -ksp_monitor_short, "
        "-ksp_monitor_true_residual, -ksp_converged_reason, -ksp_view");
  }
}

}  // namespace nlobs::reference::petsc_rules
