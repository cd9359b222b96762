#pragma once
// Plugins: a user's models, observer types, engines and problem sets in a shared library that
// the nlobs executable (or any program) loads at run time, without editing nlobs.
//
//   // my_plugin.cpp, built with nlobs_add_plugin(my_plugin my_plugin.cpp) (docs/extending.md)
//   #include "nlobs/registry/plugin.hpp"
//   #include "nlobs/registry/register_model.hpp"
//   void register_my_plugin(nlobs::PluginRegistrar& r) {
//     r.add_model(nlobs::model_entry(nlobs::ModelDefinition<Rossler>{.name = "rossler", ...}));
//     r.add_engine({.name = "broyden", .description = "...", .make = make_broyden});
//     r.add_problem_set({.name = "my-set", .description = "...", .problems = my_problems});
//   }
//   NLOBS_PLUGIN(register_my_plugin)
//
// What a registration function adds is staged; the host adds all of it, or nothing, after it
// checked every name against the registries (a taken name names both sources). One engine
// registration serves every size (EngineRegistry<Dynamic>, which every fixed size falls back
// to); a model registers once, whatever its sizes. The same staging serves a program that
// links its extensions in: register_extensions(function, "my program").
#include <cstdint>
#include <string>
#include <vector>

#include "nlobs/common/version.hpp"
#include "nlobs/registry/model_registry.hpp"
#include "nlobs/registry/observer_types.hpp"
#include "nlobs/registry/problem_sets.hpp"
#include "nlobs/solvers/engine_registry.hpp"

namespace nlobs {

// What one plugin registers, held until the host commits it.
class PluginRegistrar {
 public:
  void add_model(ModelEntry entry) { models_.push_back(std::move(entry)); }
  void add_observer_type(ObserverTypeEntry entry) { observer_types_.push_back(std::move(entry)); }
  void add_engine(EngineRegistry<Dynamic>::Entry entry) { engines_.push_back(std::move(entry)); }
  void add_problem_set(ProblemSetEntry entry) { problem_sets_.push_back(std::move(entry)); }

  const std::vector<ModelEntry>& models() const { return models_; }
  const std::vector<ObserverTypeEntry>& observer_types() const { return observer_types_; }
  const std::vector<EngineRegistry<Dynamic>::Entry>& engines() const { return engines_; }
  const std::vector<ProblemSetEntry>& problem_sets() const { return problem_sets_; }

 private:
  std::vector<ModelEntry> models_;
  std::vector<ObserverTypeEntry> observer_types_;
  std::vector<EngineRegistry<Dynamic>::Entry> engines_;
  std::vector<ProblemSetEntry> problem_sets_;
};

using PluginRegistration = void (*)(PluginRegistrar&);

// What NLOBS_PLUGIN exports, read by the loader before it calls anything of the plugin. The
// first two fields never change place: a library whose magic differs is not a plugin, one whose
// layout differs was built against an nlobs with another plugin interface.
struct PluginInfo {
  std::uint32_t magic;        // kPluginMagic
  std::uint32_t layout;       // kPluginLayout
  const char* nlobs_version;  // the nlobs it was built against: "0.1.0"
  const char* abi;            // compiler and standard library: plugin_abi_tag()
  PluginRegistration registration;
};

inline constexpr std::uint32_t kPluginMagic = 0x6e6c6f62;  // "nlob"
// 2: EngineOptionInfo gained aliases and Summary::engine became an EngineName (the engine
// option keys' change): a plugin built against layout 1 would misread both.
// 3: SolverOptions gained iteration_callback (an engine factory takes SolverOptions by value)
// and Status gained kStoppedByCallback.
// 4: ModelInstance gained the continuous model and its scheme (model-typed observer types), and
// the registries a plugin's entries enter became one NamedRegistry with its own lock.
// 5: Summary gained library_status and an engine entry without_common.
// 6: Engine gained set_record_trace (a virtual hook: the vtable moved), SquareSystem and
// LevenbergMarquardtEngine keep their accounts in a SolveLedger (their layouts changed), and
// WindowEstimatorOptions gained trace_first_window.
// 7: ModelInstance's scheme became DiscretizationOptions discretization (scheme and substeps),
// ModelEntry gained default_substeps and its make takes the DiscretizationOptions.
// 8: DiscretizationOptions gained absolute_tolerance and relative_tolerance (schemes dopri5 and
// sdirk3), and Scheme two values.
// 9: ObserverBuild gained output_noise (the noise a simulated run declares) and build_observer
// a parameter for it.
inline constexpr std::uint32_t kPluginLayout = 9;
inline constexpr const char* kPluginSymbol = "nlobs_plugin_info";

#define NLOBS_PLUGIN_STRINGIFY_(x) #x
#define NLOBS_PLUGIN_STRINGIFY(x) NLOBS_PLUGIN_STRINGIFY_(x)
// What must agree between a host and a plugin besides the version: the C++ standard library
// and its string ABI (std::string and std::function cross the boundary).
#if defined(__GLIBCXX__)
#define NLOBS_PLUGIN_ABI_TAG "libstdc++ cxx11-abi=" NLOBS_PLUGIN_STRINGIFY(_GLIBCXX_USE_CXX11_ABI)
#elif defined(_LIBCPP_VERSION)
#define NLOBS_PLUGIN_ABI_TAG "libc++ abi=" NLOBS_PLUGIN_STRINGIFY(_LIBCPP_ABI_VERSION)
#else
#define NLOBS_PLUGIN_ABI_TAG "unknown standard library"
#endif

// Exports the plugin's entry point; `function` is a void(nlobs::PluginRegistrar&).
#define NLOBS_PLUGIN(function)                                                           \
  extern "C" __attribute__((visibility("default"))) const ::nlobs::PluginInfo*           \
  nlobs_plugin_info() {                                                                  \
    static const ::nlobs::PluginInfo info{::nlobs::kPluginMagic, ::nlobs::kPluginLayout, \
                                          NLOBS_VERSION_STRING, NLOBS_PLUGIN_ABI_TAG,    \
                                          &(function)};                                  \
    return &info;                                                                        \
  }

// What a plugin (or a program's registration function) added, by kind.
struct LoadedPlugin {
  std::string source;  // the plugin's path, or the name a program gave
  std::vector<std::string> models, observer_types, engines, problem_sets;
};

// Runs `registration` on a fresh registrar and commits what it staged under `source`: every
// name is checked first (the registry's name rules; not taken, by a built-in, an earlier plugin
// or another entry of the same registration), then everything is added. On any error nothing
// is added. Throws InvalidInput naming `source` (a throwing registration included, or an empty
// `source`).
LoadedPlugin register_extensions(PluginRegistration registration, const std::string& source);

// Loads the shared library at `path` (RTLD_NOW: a missing symbol fails here, not mid-run),
// checks its PluginInfo (magic, layout, nlobs version, ABI tag) and commits its registration
// as register_extensions does. Throws InvalidInput naming the plugin: a path that does not
// exist, a library that cannot be loaded, one that is not an nlobs plugin, one built against
// another nlobs, a registration that throws or registers a taken name. A library that dlopen
// loaded stays mapped for the life of the process, refused or not (its code may still be
// referred to); nothing of a refused one is registered. Loading the same file twice is an
// error (its names are taken). A registration function must add through the registrar only:
// what it adds to the global registries directly escapes the checks.
LoadedPlugin load_plugin(const std::string& path);

// The plugins a ':'-separated list names (NLOBS_PLUGIN_PATH): each item a plugin file, or a
// directory whose *.so files are loaded in name order; empty items are skipped.
std::vector<LoadedPlugin> load_plugin_path(const std::string& list);

}  // namespace nlobs
