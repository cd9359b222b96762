#pragma once
// The example plugin's registrations, one per file (they compile in parallel).
#include "nlobs/registry/plugin.hpp"

namespace example {

void add_fitzhugh_nagumo(nlobs::PluginRegistrar& registrar);   // fitzhugh_nagumo_entry.cpp
void add_bad_broyden(nlobs::PluginRegistrar& registrar);       // bad_broyden_entry.cpp
void add_example_problems(nlobs::PluginRegistrar& registrar);  // example_problems.cpp
void add_output_injection(nlobs::PluginRegistrar& registrar);  // output_injection_entry.cpp
void add_fixed_size_ekf(nlobs::PluginRegistrar& registrar);    // fixed_size_ekf_entry.cpp

}  // namespace example
