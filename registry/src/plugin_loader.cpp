#include <dlfcn.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <set>
#include <string>
#include <system_error>
#include <vector>

#include "nlobs/common/file_type.hpp"
#include "nlobs/common/printable.hpp"
#include "nlobs/common/registry_name.hpp"
#include "nlobs/registry/plugin.hpp"
#include "nlobs/solvers/library_sizes.hpp"
#include "nlobs/solvers/status.hpp"
#include "plugin_file.hpp"

namespace nlobs {
namespace {

// A plugin's path as the registries keep it (its entries' source, `nlobs list`'s "from …"):
// printable, so that a path with a control character cannot forge a line, and long enough
// (PATH_MAX) that two plugins never share one.
constexpr std::size_t kSourceLimit = 4096;

// Each staged entry as its registry's add() would take it (NamedRegistry::refusal: the name
// rule, a complete entry, a name not taken), and no name twice in the same registration: checked
// for the whole registration before anything is added.
template <typename Entry, typename Refusal>
void check_entries(const std::vector<Entry>& staged, const std::string& kind,
                   const std::string& source, Refusal refusal) {
  std::set<std::string> seen;
  for (const Entry& e : staged) {
    if (std::string why = refusal(e); !why.empty()) throw InvalidInput(why);
    if (!seen.insert(e.name).second) {
      throw InvalidInput(kind + " '" + e.name + "' is registered twice by " + source);
    }
  }
}

template <typename Registry, typename Entry>
void check_registry(const std::vector<Entry>& staged, const Registry& registry,
                    const std::string& source) {
  check_entries(staged, registry.kind(), source,
                [&](const Entry& e) { return registry.refusal(e, source); });
}

// An engine is refused as EngineRegistry<Dynamic>::add refuses it, and also when an entry at a
// fixed size the library serves has its name (it would shadow the plugin's Dynamic entry there).
std::string engine_refusal(const EngineRegistry<Dynamic>::Entry& e, const std::string& source) {
  if (std::string why = EngineRegistry<Dynamic>::global().refusal(e, source); !why.empty()) {
    return why;
  }
  std::string holder;
#define NLOBS_ENGINE_SOURCE_AT(n)                                                          \
  if (holder.empty() && (n) != Dynamic && EngineRegistry<n>::global().has_entry(e.name)) { \
    holder = EngineRegistry<n>::global().source(e.name) + " (at size " #n ")";             \
  }
  NLOBS_FOR_EACH_LIBRARY_SIZE(NLOBS_ENGINE_SOURCE_AT)
#undef NLOBS_ENGINE_SOURCE_AT
  if (holder.empty()) return {};
  return "engine '" + e.name + "' from " + printable(source) + " is already registered by " +
         printable(holder);
}

void check_staged(const PluginRegistrar& staged, const std::string& source) {
  check_registry(staged.models(), model_registry(), source);
  check_registry(staged.observer_types(), observer_type_registry(), source);
  check_registry(staged.problem_sets(), problem_set_registry(), source);
  check_entries(staged.engines(), "engine", source,
                [&source](const auto& e) { return engine_refusal(e, source); });
}

// One registration at a time, checked and committed under one lock: two plugins loaded on two
// threads cannot both pass the check with the same name. (A program that adds to a registry
// directly while a plugin loads can still take a name between the check and the commit; the
// commit then fails part-way, naming it.)
LoadedPlugin commit(const PluginRegistrar& staged, const std::string& source) {
  static std::mutex loading;
  std::lock_guard<std::mutex> lock(loading);
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

// A user's text as the loader echoes it: quoted, printable, at most kPrintableLimit bytes.
std::string quoted(const std::string& text) {
  return quoted_excerpt(text, kPrintableLimit);
}

// What a stat or fstat says a path is, when it is not a file dlopen can be given: dlopen on a
// FIFO blocks forever waiting for a writer, on a device it reads whatever the device gives.
std::string not_a_file(mode_t mode) {
  if (S_ISREG(mode)) return {};
  if (S_ISDIR(mode)) return "is a directory (NLOBS_PLUGIN_PATH takes directories)";
  return std::string("is ") + file_type_name(mode) + ", not a shared library";
}

// Closes the descriptor it holds when it goes out of scope.
struct FileDescriptor {
  int fd = -1;
  ~FileDescriptor() {
    if (fd >= 0) ::close(fd);
  }
};

// Why the file at `file` (an absolute path, already stat'ed as a regular file) must not be
// given to dlopen; empty when it may. The checks read an open descriptor, not the path again:
// O_NONBLOCK so that a path swapped for a FIFO since the stat cannot block the open, fstat so
// that what is checked is what was opened.
std::string file_problem(const std::string& file) {
  FileDescriptor opened{::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY)};
  if (opened.fd < 0) return std::string("cannot be read: ") + std::strerror(errno);
  struct stat status {};
  if (::fstat(opened.fd, &status) != 0) {
    return std::string("cannot be read: ") + std::strerror(errno);
  }
  if (std::string kind = not_a_file(status.st_mode); !kind.empty()) return kind;
  const auto read_at = [fd = opened.fd](std::uint64_t offset, std::size_t count, void* out) {
    auto* bytes = static_cast<char*>(out);
    while (count > 0) {
      const ssize_t got = ::pread(fd, bytes, count, static_cast<off_t>(offset));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) return false;  // an error, or the file shrank since fstat
      bytes += got;
      offset += static_cast<std::uint64_t>(got);
      count -= static_cast<std::size_t>(got);
    }
    return true;
  };
  const std::string problem =
      plugin_file::elf_problem(static_cast<std::uint64_t>(status.st_size), read_at);
  return problem.empty() ? problem : "it " + problem;
}

// register_extensions with `source` already made printable (the loader's, up to kSourceLimit).
LoadedPlugin register_printable(PluginRegistration registration, const std::string& source) {
  if (registration == nullptr) {
    throw InvalidInput(source + ": no registration function");
  }
  PluginRegistrar staged;
  try {
    registration(staged);
  } catch (...) {  // of any type: a plugin may throw anything
    throw InvalidInput(source + ": its registration threw: " + current_exception_text() +
                       " (nothing of it was registered)");
  }
  try {
    return commit(staged, source);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string(e.what()) + " (nothing of " + source + " was registered)");
  }
}

}  // namespace

LoadedPlugin register_extensions(PluginRegistration registration, const std::string& source) {
  if (source.empty()) throw InvalidInput("register_extensions: the source has no name");
  return register_printable(registration, printable(source, kSourceLimit));
}

LoadedPlugin load_plugin(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InvalidInput("plugin path is empty");
  const std::string named = "plugin " + quoted(path);
  // stat, not lstat: a link to a plugin is a plugin, a link to a FIFO is a FIFO.
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) {
    const int error = errno;
    if (error == ENOENT) throw InvalidInput(named + ": no such file");
    throw InvalidInput(named + " cannot be read: " + std::strerror(error));
  }
  if (const std::string kind = not_a_file(status.st_mode); !kind.empty()) {
    throw InvalidInput(named + " " + kind);
  }
  // An absolute path: dlopen searches the library path for a name without '/', and the
  // registries name this file as the source of its entries.
  std::error_code ec;
  fs::path absolute = fs::absolute(path, ec);
  const std::string file = ec ? path : absolute.lexically_normal().string();
  const std::string plugin = "plugin " + quoted(file);
  const std::string source = printable(file, kSourceLimit);

  // The file's type and ELF headers are checked on a descriptor, then dlopen is given the path
  // (not /proc/self/fd/N: the library keeps the name it is loaded by, for $ORIGIN in its
  // RUNPATH, for dladdr and backtraces, and for dlopen's own "already loaded" check). Whoever
  // can swap the file between the two can as well write code into it.
  if (const std::string problem = file_problem(file); !problem.empty()) {
    throw InvalidInput(plugin + " cannot be loaded: " + problem);
  }

  // A library that loaded is never unloaded, refused or not: its static constructors have run,
  // an exception or an entry may still refer to its code, and template statics (GNU unique
  // symbols) would keep it mapped anyway. Nothing of a refused one is registered.
  dlerror();
  void* library = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!library) {
    const char* why = dlerror();
    throw InvalidInput(plugin + " cannot be loaded: " + (why ? printable(why) : "dlopen failed"));
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
    throw InvalidInput(plugin + " is not an nlobs plugin: its " + kPluginSymbol +
                       " threw: " + current_exception_text());
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
    return register_printable(info->registration, source);
  } catch (const InvalidInput& e) {
    throw InvalidInput(plugin + " refused: " + e.what());
  } catch (...) {  // out of memory while its entries were added
    throw InvalidInput(plugin + " could not be registered: " + current_exception_text());
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
        // Every *.so but a directory: a FIFO, device or socket among them is refused by
        // load_plugin by name (not skipped: a plugin the user put there would go missing
        // silently, and dlopen would block on a FIFO).
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
