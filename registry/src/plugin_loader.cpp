#include <dlfcn.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <system_error>
#include <vector>

#include "nlobs/registry/plugin.hpp"
#include "nlobs/solvers/library_sizes.hpp"

namespace nlobs {
namespace {

// Every name the staged registration adds, checked before anything is added: the registry's
// name rule, not taken (by whom), not twice in the same registration.
template <typename Entry, typename Taken>
void check_names(const std::vector<Entry>& staged, const std::string& kind,
                 const std::string& source, Taken taken_by) {
  std::set<std::string> seen;
  for (const Entry& e : staged) {
    if (!seen.insert(e.name).second) {
      throw InvalidInput(kind + " '" + e.name + "' is registered twice by " + source);
    }
    if (const std::optional<std::string> other = taken_by(e.name)) {
      throw InvalidInput(kind + " '" + e.name + "' from " + source + " is already registered by " +
                         (other->empty() ? std::string("an unnamed source") : *other));
    }
  }
}

template <typename Entry>
void check_registry_names(const std::vector<Entry>& staged, const NamedRegistry<Entry>& registry,
                          const std::string& source) {
  for (const Entry& e : staged) {
    if (!is_registry_name(e.name)) {
      throw InvalidInput(registry.kind() + " name '" + e.name.substr(0, 60) + "' from " + source +
                         " is empty or has characters other than letters, digits and _ . + -");
    }
  }
  check_names(staged, registry.kind(), source,
              [&registry](const std::string& name) -> std::optional<std::string> {
                if (!registry.contains(name)) return std::nullopt;
                return registry.source(name);
              });
}

// The source that has an engine of this name at any size the library serves (an entry at a
// fixed size would shadow the plugin's Dynamic entry there); none when the name is free.
std::optional<std::string> engine_source(const std::string& name) {
  if (EngineRegistry<Dynamic>::global().has_entry(name)) {
    return EngineRegistry<Dynamic>::global().source(name);
  }
  std::optional<std::string> source;
#define NLOBS_ENGINE_SOURCE_AT(n)                                                 \
  if (!source && (n) != Dynamic && EngineRegistry<n>::global().has_entry(name)) { \
    source = EngineRegistry<n>::global().source(name) + " (at size " #n ")";      \
  }
  NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_ENGINE_SOURCE_AT)
#undef NLOBS_ENGINE_SOURCE_AT
  return source;
}

void check_staged(const PluginRegistrar& staged, const std::string& source) {
  check_registry_names(staged.models(), model_registry(), source);
  check_registry_names(staged.observer_types(), observer_type_registry(), source);
  check_registry_names(staged.problem_sets(), problem_set_registry(), source);
  for (const auto& e : staged.engines()) {
    if (e.name.empty() || e.name.find_first_of(":,=") != std::string::npos) {
      throw InvalidInput("engine name '" + e.name.substr(0, 60) + "' from " + source +
                         " is empty or contains ':', ',' or '='");
    }
    if (!e.make) throw InvalidInput("engine '" + e.name + "' from " + source + " has no factory");
  }
  check_names(staged.engines(), "engine", source, engine_source);
  for (const auto& e : staged.problem_sets()) {
    if (!e.problems) {
      throw InvalidInput("problem set '" + e.name + "' from " + source + " has no problems()");
    }
  }
  for (const auto& e : staged.models()) {
    if (!e.make) throw InvalidInput("model '" + e.name + "' from " + source + " has no make");
  }
  for (const auto& e : staged.observer_types()) {
    if (!e.parse || !e.write || !e.build) {
      throw InvalidInput("observer type '" + e.name + "' from " + source +
                         " needs parse, write and build");
    }
  }
}

LoadedPlugin commit(const PluginRegistrar& staged, const std::string& source) {
  check_staged(staged, source);
  LoadedPlugin loaded{source, {}, {}, {}, {}};
  for (const auto& e : staged.models()) {
    model_registry().add(e, source);
    loaded.models.push_back(e.name);
  }
  for (const auto& e : staged.observer_types()) {
    observer_type_registry().add(e, source);
    loaded.observer_types.push_back(e.name);
  }
  for (const auto& e : staged.engines()) {
    EngineRegistry<Dynamic>::global().add(e, source);
    loaded.engines.push_back(e.name);
  }
  for (const auto& e : staged.problem_sets()) {
    problem_set_registry().add(e, source);
    loaded.problem_sets.push_back(e.name);
  }
  return loaded;
}

std::string quoted(const std::string& text) {
  return "'" + (text.size() > 200 ? text.substr(0, 200) + "…" : text) + "'";
}

}  // namespace

LoadedPlugin register_extensions(PluginRegistration registration, const std::string& source) {
  if (source.empty()) throw InvalidInput("register_extensions: the source has no name");
  if (registration == nullptr) {
    throw InvalidInput(source + ": no registration function");
  }
  PluginRegistrar staged;
  try {
    registration(staged);
  } catch (const std::exception& e) {
    throw InvalidInput(source + ": its registration threw: " + std::string(e.what()) +
                       " (nothing of it was registered)");
  } catch (...) {
    throw InvalidInput(source +
                       ": its registration threw a non-standard exception (nothing of it was "
                       "registered)");
  }
  try {
    return commit(staged, source);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string(e.what()) + " (nothing of " + source + " was registered)");
  }
}

LoadedPlugin load_plugin(const std::string& path) {
  namespace fs = std::filesystem;
  const std::string named = "plugin " + quoted(path);
  std::error_code ec;
  if (path.empty()) throw InvalidInput("plugin path is empty");
  const fs::file_status status = fs::status(path, ec);
  if (status.type() == fs::file_type::not_found) throw InvalidInput(named + ": no such file");
  if (ec) throw InvalidInput(named + " cannot be read: " + ec.message());
  if (fs::is_directory(status)) {
    throw InvalidInput(named + " is a directory (NLOBS_PLUGIN_PATH takes directories)");
  }
  // An absolute path: dlopen searches the library path for a name without '/', and the
  // registries name this file as the source of its entries.
  fs::path absolute = fs::absolute(path, ec);
  const std::string file = ec ? path : absolute.lexically_normal().string();
  const std::string plugin = "plugin " + quoted(file);

  // A library that loaded is never unloaded, refused or not: its static constructors have run,
  // an exception or an entry may still refer to its code, and template statics (GNU unique
  // symbols) would keep it mapped anyway. Nothing of a refused one is registered.
  dlerror();
  void* library = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!library) {
    const char* why = dlerror();
    throw InvalidInput(plugin + " cannot be loaded: " + (why ? why : "dlopen failed"));
  }
  using InfoFunction = const PluginInfo* (*)();
  void* symbol = dlsym(library, kPluginSymbol);
  if (!symbol) {
    throw InvalidInput(plugin + " is not an nlobs plugin: it exports no " + kPluginSymbol +
                       " (build it with nlobs_add_plugin and NLOBS_PLUGIN, docs/extending.md)");
  }
  const PluginInfo* info = nullptr;
  try {
    info = reinterpret_cast<InfoFunction>(symbol)();
  } catch (...) {
    throw InvalidInput(plugin + " is not an nlobs plugin: its " + kPluginSymbol + " threw");
  }
  if (info == nullptr || info->magic != kPluginMagic) {
    throw InvalidInput(plugin + " is not an nlobs plugin: its " + kPluginSymbol +
                       " does not describe one");
  }
  if (info->layout != kPluginLayout) {
    throw InvalidInput(plugin + " was built for nlobs plugin interface " +
                       std::to_string(info->layout) + "; this nlobs has interface " +
                       std::to_string(kPluginLayout) + ": rebuild it against this nlobs");
  }
  const std::string version = info->nlobs_version ? info->nlobs_version : "(none)";
  if (version != NLOBS_VERSION_STRING) {
    throw InvalidInput(plugin + " was built against nlobs " + quoted(version) +
                       "; this is nlobs " NLOBS_VERSION_STRING ": rebuild it against this nlobs");
  }
  const std::string abi = info->abi ? info->abi : "(none)";
  if (abi != NLOBS_PLUGIN_ABI_TAG) {
    throw InvalidInput(plugin + " was built with " + quoted(abi) + "; this nlobs with '" +
                       NLOBS_PLUGIN_ABI_TAG + "': rebuild it with the same compiler setup");
  }
  try {
    return register_extensions(info->registration, file);
  } catch (const InvalidInput& e) {
    throw InvalidInput(plugin + " refused: " + e.what());
  } catch (const std::exception& e) {  // out of memory while its entries were added
    throw InvalidInput(plugin + " could not be registered: " + e.what());
  }
}

std::vector<LoadedPlugin> load_plugin_path(const std::string& list) {
  namespace fs = std::filesystem;
  std::vector<LoadedPlugin> loaded;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(':', begin), list.size());
    const std::string item = list.substr(begin, end - begin);
    begin = end + 1;
    if (item.empty()) continue;
    std::error_code ec;
    if (fs::is_directory(item, ec)) {
      std::vector<std::string> files;
      fs::directory_iterator it(item, ec), last;
      for (; !ec && it != last; it.increment(ec)) {
        std::error_code kind;
        if (it->path().extension() == ".so" && !it->is_directory(kind)) {
          files.push_back(it->path().string());
        }
      }
      if (ec) {
        throw InvalidInput("NLOBS_PLUGIN_PATH directory " + quoted(item) +
                           " cannot be read: " + ec.message());
      }
      std::sort(files.begin(), files.end());
      for (const auto& f : files) loaded.push_back(load_plugin(f));
    } else {
      loaded.push_back(load_plugin(item));
    }
  }
  return loaded;
}

}  // namespace nlobs
