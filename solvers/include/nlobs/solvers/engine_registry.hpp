#pragma once
// Engines by name: EngineRegistry<N>::global().create("anderson:m=3,damping=0.5").
// Every built-in engine is registered; a user registers their own under its own name with
// add(). Options common to all engines, named after StopCriteria's fields: step_tolerance (alias
// tol), residual_tolerance (ftol), max_iterations (max_iter), max_evaluations (max_evals),
// progress_window. An engine's own option under a common option's key replaces that option on
// that engine, aliases included; under one of its aliases, it takes that alias only
// (levenberg-marquardt:ftol is MINPACK's ftol, its function_tolerance; residual_tolerance is
// still the common one there).
//
// One registration serves every size: a fixed-size registry EngineRegistry<N> that has no entry
// of a name uses the entry of EngineRegistry<Dynamic> through DynamicSizeEngine<N>. An entry
// added at a fixed size N shadows it there (allocation-free engines for that size). The
// built-in engines have their own entries at the library's sizes (library_sizes.hpp); at
// other sizes they come through the fallback, or as fixed-size engines after
// add_builtin_engines<N>(EngineRegistry<N>::global()) from builtin_engines.hpp.
//
// The registry is a NamedRegistry (nlobs/common/named_registry.hpp), as every registry of nlobs
// is: its name rule, its error type (InvalidInput) and its thread rule (any member from any
// thread, add() included; create() builds a new engine each call) are that one's.
//
// This header names no engine: the engines are compiled once, in the solvers library.
#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "nlobs/common/named_registry.hpp"
#include "nlobs/common/printable.hpp"
#include "nlobs/solvers/dynamic_size_engine.hpp"
#include "nlobs/solvers/engine.hpp"
#include "nlobs/solvers/engine_spec.hpp"
#include "nlobs/solvers/library_sizes.hpp"

namespace nlobs {

template <int N>
class EngineRegistry;

// Adds every built-in engine (`nlobs list engines`) to `registry`, skipping names it already has.
// Defined in builtin_engines.hpp; compiled in the library for its sizes.
template <int N>
void add_builtin_engines(EngineRegistry<N>& registry);

template <int N = Dynamic>
class EngineRegistry {
 public:
  using Factory = std::function<std::unique_ptr<Engine<N>>(EngineSpecReader&, SolverOptions)>;
  // Designated initialisers may leave out any field: {.name = ..., .make = ...}.
  struct Entry {
    std::string name{};
    std::string description{};
    std::vector<EngineOptionInfo> options{};  // engine-specific; the common ones are added
    std::vector<std::string> examples{};      // spec strings shown by `nlobs list engines`
    Factory make{};
    // Common options the engine does not take (EngineDescription::without_common): refused in a
    // spec as unknown options.
    std::vector<std::string> without_common{};

    // NamedRegistry refuses an entry without a factory.
    friend std::string missing_part(const Entry& e) {
      return e.make ? std::string() : std::string("has no factory");
    }
  };

  // The process-wide registry, with every built-in engine.
  static EngineRegistry& global() {
    static EngineRegistry registry(WithBuiltins{});
    return registry;
  }

  static const std::vector<EngineOptionInfo>& common_options() {
    static const std::vector<EngineOptionInfo> common = {
        {"step_tolerance", "step tolerance, max norm; default 1e-8", {"tol"}},
        {"residual_tolerance", "residual tolerance ‖F‖∞; default off", {"ftol"}},
        {"max_iterations", "maximum iterations; default 10000", {"max_iter"}},
        {"max_evaluations", "maximum function evaluations; default 100000", {"max_evals"}},
        {"progress_window",
         "evaluations without a 0.1 % fall of |F|_2 before a Jacobian-based engine stops "
         "stagnated, 0 = off; default 50"}};
    return common;
  }

  // Throws InvalidInput if the name breaks the registry name rule (registry_name.hpp), is taken
  // (naming both sources), or the factory is empty. `source` says who registered it: "built-in", a
  // plugin's path, a program.
  void add(Entry entry, std::string source = "built-in") {
    store_.add(std::move(entry), std::move(source));
  }
  // add()'s message for `entry`, empty when add() would take it (NamedRegistry::refusal).
  std::string refusal(const Entry& entry, const std::string& source) const {
    return store_.refusal(entry, source);
  }

  // The source that registered `name` in this registry (empty when none did).
  std::string source(const std::string& name) const { return store_.source(name); }

  // Whether create() knows the name (here or, for a fixed N, at Dynamic).
  bool contains(const std::string& name) const { return find(name).has_value(); }
  // Whether this registry has an entry of its own under the name (add() would refuse it).
  bool has_entry(const std::string& name) const { return store_.contains(name); }

  // This registry's entries and, for a fixed N, those of EngineRegistry<Dynamic> it does not
  // shadow (their factories adapt the Dynamic engine); sorted by name.
  std::vector<Entry> entries() const;

  std::vector<std::string> names() const;

  // Builds the engine a spec names; `base` supplies stop criteria the spec does not set. The
  // engine's label() is the spec as given.
  // Throws InvalidInput for an unknown name (listing the valid ones) or option, and for anything
  // the entry's factory throws (a user's: named with its source).
  std::unique_ptr<Engine<N>> create(std::string_view spec_text, SolverOptions base = {}) const;

 private:
  std::optional<Entry> find(const std::string& name) const;

  // An entry of EngineRegistry<Dynamic> seen at size N.
  template <typename DynamicEntry>
  static Entry adapt(DynamicEntry e) {
    auto make = std::move(e.make);
    return {std::move(e.name),
            std::move(e.description),
            std::move(e.options),
            std::move(e.examples),
            [make = std::move(make)](EngineSpecReader& s,
                                     SolverOptions o) -> std::unique_ptr<Engine<N>> {
              std::unique_ptr<Engine<Dynamic>> engine;
              try {
                engine = make(s, std::move(o));
              } catch (const InvalidInput& refused) {
                throw InvalidInput(
                    std::string(refused.what()) + " (EngineRegistry<" + std::to_string(N) +
                    "> serves this engine through its Dynamic entry; give size " +
                    std::to_string(N) + " its own entry, for the built-ins add_builtin_engines<" +
                    std::to_string(N) + ">() from builtin_engines.hpp)");
              }
              if (!engine) return nullptr;
              return std::make_unique<DynamicSizeEngine<N>>(std::move(engine));
            },
            std::move(e.without_common)};
  }

  struct WithBuiltins {};
  explicit EngineRegistry(WithBuiltins) {
    if constexpr (is_library_size(N)) add_builtin_engines<N>(*this);
  }

  NamedRegistry<Entry> store_{"engine"};
};

// The entry of an engine type E (an Engine<N>) built as the built-ins are: E(options, solver
// options), its options type E::Options giving
//   static EngineDescription describe();     // name, one line, spec keys, examples
//   void read(EngineSpecReader& spec);       // the spec's items over the current values
// (and validate(), which E's constructor calls); or, for an engine without options of its own,
// E(solver options) and a static E::describe(). A user's engine of this shape registers with
//   registry.add(engine_entry<Dynamic, MyEngine<>>(), "my program");
template <int N, typename E>
typename EngineRegistry<N>::Entry engine_entry() {
  if constexpr (requires { typename E::Options; }) {
    using Options = typename E::Options;
    EngineDescription d = Options::describe();
    return {std::move(d.name),
            std::move(d.description),
            std::move(d.options),
            std::move(d.examples),
            [](EngineSpecReader& spec, SolverOptions solver) {
              Options options;
              options.read(spec);
              return std::unique_ptr<Engine<N>>(
                  std::make_unique<E>(std::move(options), std::move(solver)));
            },
            std::move(d.without_common)};
  } else {
    EngineDescription d = E::describe();
    return {std::move(d.name),
            std::move(d.description),
            std::move(d.options),
            std::move(d.examples),
            [](EngineSpecReader&, SolverOptions solver) {
              return std::unique_ptr<Engine<N>>(std::make_unique<E>(std::move(solver)));
            },
            std::move(d.without_common)};
  }
}

template <int N>
auto EngineRegistry<N>::entries() const -> std::vector<Entry> {
  std::map<std::string, Entry> all;
  if constexpr (N != Dynamic) {
    for (auto& e : EngineRegistry<Dynamic>::global().entries()) {
      std::string name = e.name;
      all.emplace(std::move(name), adapt(std::move(e)));
    }
  }
  for (const Entry* e : store_.entries()) all.insert_or_assign(e->name, *e);
  std::vector<Entry> out;
  for (auto& [name, e] : all) out.push_back(std::move(e));
  return out;
}

template <int N>
std::vector<std::string> EngineRegistry<N>::names() const {
  std::vector<std::string> out;
  for (const auto& e : entries()) out.push_back(e.name);
  return out;
}

template <int N>
std::unique_ptr<Engine<N>> EngineRegistry<N>::create(std::string_view spec_text,
                                                     SolverOptions base) const {
  const EngineSpec spec = parse_engine_spec(spec_text);
  std::optional<Entry> entry = find(spec.name);
  if (!entry) {
    std::string list;
    for (const auto& name : names()) list += (list.empty() ? "" : ", ") + name;
    throw InvalidInput(store_.unknown_refusal(spec.name, list));
  }
  std::vector<EngineOptionInfo> valid = entry->options;
  const auto engine_names = [&entry](const std::string& name) {
    for (const auto& o : entry->options) {
      if (o.key == name || std::find(o.aliases.begin(), o.aliases.end(), name) != o.aliases.end())
        return true;
    }
    return false;
  };
  std::vector<std::string> common_keys;  // those the engine leaves to the common options
  const auto& without = entry->without_common;
  for (EngineOptionInfo common : common_options()) {
    if (engine_names(common.key)) continue;
    if (std::find(without.begin(), without.end(), common.key) != without.end()) continue;
    std::erase_if(common.aliases, engine_names);
    common_keys.push_back(common.key);
    valid.push_back(std::move(common));
  }
  const auto common_key = [&common_keys](const char* key) {
    return std::find(common_keys.begin(), common_keys.end(), key) != common_keys.end();
  };
  EngineSpecReader reader(spec, valid);
  if (common_key("step_tolerance")) {
    if (auto v = reader.number("step_tolerance")) base.stop.step_tolerance = *v;
  }
  if (common_key("residual_tolerance")) {
    if (auto v = reader.number("residual_tolerance")) base.stop.residual_tolerance = *v;
  }
  if (common_key("max_iterations")) {
    if (auto v = reader.integer("max_iterations", 1, 1000000000)) base.stop.max_iterations = *v;
  }
  if (common_key("max_evaluations")) {
    if (auto v = reader.integer("max_evaluations", 1, 1000000000)) base.stop.max_evaluations = *v;
  }
  if (common_key("progress_window")) {
    if (auto v = reader.integer("progress_window", 0, 1000000000)) base.stop.progress_window = *v;
  }
  std::unique_ptr<Engine<N>> engine;
  try {
    engine = entry->make(reader, std::move(base));
  } catch (const InvalidInput&) {  // a refused option: the reader's message names it
    throw;
  } catch (...) {  // a user's factory (a plugin's): anything it throws, named by the engine
    const std::string from = source(spec.name);
    throw InvalidInput("engine '" + spec.name + "'" +
                       (from.empty() || from == "built-in" ? "" : " from " + printable(from)) +
                       ": its factory threw: " + current_exception_text());
  }
  reader.finish();
  if (!engine) throw InvalidInput("engine '" + spec.name + "': its factory returned no engine");
  engine->set_label(std::string(spec_text));
  return engine;
}

template <int N>
auto EngineRegistry<N>::find(const std::string& name) const -> std::optional<Entry> {
  if (const Entry* own = store_.find(name)) return *own;
  if constexpr (N != Dynamic) {
    for (auto& e : EngineRegistry<Dynamic>::global().entries()) {
      if (e.name == name) return adapt(std::move(e));
    }
  }
  return std::nullopt;
}

// Compiled once in the library for its sizes (nlobs/solvers/library_sizes.hpp).
#define NLOBS_EXTERN_ENGINE_REGISTRY(n)    \
  extern template class EngineRegistry<n>; \
  extern template void add_builtin_engines<n>(EngineRegistry<n>&);
NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_EXTERN_ENGINE_REGISTRY)
#undef NLOBS_EXTERN_ENGINE_REGISTRY

}  // namespace nlobs
