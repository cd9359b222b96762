// The example plugin's entry point: `nlobs --plugin libnlobs_example_plugin.so list` shows a
// model (fitzhugh-nagumo), an engine (bad-broyden, Broyden's second method), an observer type
// (output_injection), an observer type built on the model's own C++ type (fixed_size_ekf) and a
// problem set (example) beside the built-ins.
#include "example_plugin.hpp"

namespace {

void register_example_plugin(nlobs::PluginRegistrar& registrar) {
  example::add_fitzhugh_nagumo(registrar);
  example::add_bad_broyden(registrar);
  example::add_example_problems(registrar);
  example::add_output_injection(registrar);
  example::add_fixed_size_ekf(registrar);
}

}  // namespace

NLOBS_PLUGIN(register_example_plugin)
