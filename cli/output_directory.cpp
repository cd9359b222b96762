#include "output_directory.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <system_error>

namespace nlobs::cli {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kTemporarySuffix = ".tmp";

// Temporaries the signal handler removes. The handler may only read what is lock-free and
// call async-signal-safe functions (kill, waitpid, unlink, raise): a fixed table of paths,
// each published by an atomic flag after it is copied.
constexpr std::size_t kSlots = 64, kPathLength = 4096;
struct Slot {
  std::atomic<bool> used{false};
  std::array<char, kPathLength> path{};
};
std::array<Slot, kSlots> g_slots;
std::atomic<pid_t> g_child{0};
std::mutex g_slots_mutex;  // between registering threads, never taken by the handler
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<pid_t>::is_always_lock_free);

// The slot holding `path`, or -1 when the table is full or the path too long (then a signal
// may leave that temporary; the next run into the directory removes it).
int register_temporary(const fs::path& path) {
  const std::string& text = path.native();
  if (text.size() >= kPathLength) return -1;
  const std::lock_guard<std::mutex> lock(g_slots_mutex);
  for (std::size_t i = 0; i < kSlots; ++i) {
    if (g_slots[i].used.load()) continue;
    std::memcpy(g_slots[i].path.data(), text.c_str(), text.size() + 1);
    g_slots[i].used.store(true);
    return static_cast<int>(i);
  }
  return -1;
}

void unregister_temporary(int slot) {
  if (slot >= 0) g_slots[static_cast<std::size_t>(slot)].used.store(false);
}

extern "C" void remove_temporaries_and_reraise(int signal_number) {
  const int saved_errno = errno;
  if (const pid_t child = g_child.load(); child > 0) {
    ::kill(child, SIGKILL);
    int status = 0;
    while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
    }
  }
  for (Slot& slot : g_slots) {
    if (slot.used.load()) ::unlink(slot.path.data());
  }
  errno = saved_errno;
  // SA_RESETHAND restored the default action: the signal, pending until we return, then
  // ends the process as it would have without us (exit status by signal).
  ::raise(signal_number);
}

std::string temporary_name(const std::string& name) {
  return name + std::string(kTemporarySuffix);
}

std::string reason(int error) {
  return error != 0 ? std::strerror(error) : "input/output error";
}

bool is_signals_png(std::string_view name) {  // signals_<digits>.png
  constexpr std::string_view prefix = "signals_", suffix = ".png";
  if (name.size() <= prefix.size() + suffix.size() || !name.starts_with(prefix) ||
      !name.ends_with(suffix)) {
    return false;
  }
  const std::string_view digits =
      name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
  return std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// Removes a file (or a link) of that name; a directory of that name is the user's and stays.
void remove_file(const fs::path& p) {
  std::error_code ec;
  if (fs::is_directory(fs::symlink_status(p, ec))) return;
  fs::remove(p, ec);
  if (ec) throw std::runtime_error("cannot remove " + p.string() + ": " + ec.message());
}

}  // namespace

const std::vector<std::string>& output_file_names() {
  static const std::vector<std::string> names = {
      "summary.json",  "trajectories.csv", "plot_data.csv", "first_window.dat",
      "scenario.json", "plots.gp",         "gnuplot.log",   "states.png",
      "errors.png",    "z_error.png",      "eta_error.png", "first_window.png",
      "sweep.csv",     "sweep.dat",        "sweep.gp",      "sweep.png"};
  return names;
}

bool is_output_file_name(std::string_view name) {
  if (name.ends_with(kTemporarySuffix)) name.remove_suffix(kTemporarySuffix.size());
  const auto& names = output_file_names();
  return is_signals_png(name) || std::find(names.begin(), names.end(), name) != names.end();
}

void install_interrupt_cleanup() {
  struct sigaction action {};
  action.sa_handler = remove_temporaries_and_reraise;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  for (const int s : {SIGINT, SIGTERM, SIGHUP}) {
    // A signal the caller ignores (nohup, a background job's SIGINT) stays ignored.
    struct sigaction previous {};
    if (::sigaction(s, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
    ::sigaction(s, &action, nullptr);
  }
}

void set_interruptible_child(pid_t pid) {
  g_child.store(pid);
}

// ---------------------------------------------------------------------------------------------

struct OutputDirectory::Writer::State {
  OutputDirectory* owner;
  std::string name;
  fs::path final_path, temporary;
  std::ofstream out;
  int slot = -1;
};

OutputDirectory::Writer::Writer(std::unique_ptr<State> state) : state_(std::move(state)) {}
OutputDirectory::Writer::Writer(Writer&&) noexcept = default;

OutputDirectory::Writer::~Writer() {
  if (!state_) return;
  state_->out.close();
  std::error_code ignored;
  fs::remove(state_->temporary, ignored);
  unregister_temporary(state_->slot);
}

std::ostream& OutputDirectory::Writer::stream() {
  return state_->out;
}

void OutputDirectory::Writer::commit() {
  State& s = *state_;
  errno = 0;
  s.out.flush();
  if (!s.out) {
    throw std::runtime_error("writing " + s.temporary.string() + " failed: " + reason(errno));
  }
  s.out.close();
  if (s.out.fail()) {
    throw std::runtime_error("writing " + s.temporary.string() + " failed: " + reason(errno));
  }
  std::error_code ec;
  fs::rename(s.temporary, s.final_path, ec);
  if (ec) {
    throw std::runtime_error("cannot rename " + s.temporary.string() + " to " +
                             s.final_path.string() + ": " + ec.message());
  }
  unregister_temporary(s.slot);
  s.owner->note_written(s.name);
  state_.reset();
}

// ---------------------------------------------------------------------------------------------

OutputDirectory::OutputDirectory(const std::string& path) : path_(fs::absolute(path)) {
  std::error_code ec;
  fs::create_directories(path_, ec);
  if (ec) throw std::runtime_error("cannot create " + path_.string() + ": " + ec.message());
  if (!fs::is_directory(path_)) {
    throw std::runtime_error("cannot write into " + path_.string() + ": not a directory");
  }
  // From here on the directory is incomplete until its marker is written again.
  remove_file(path_ / "summary.json");
  remove_file(path_ / "sweep.csv");
  for (const std::string& name : output_file_names()) {
    remove_file(path_ / temporary_name(name));
  }
}

OutputDirectory::~OutputDirectory() {
  try {
    discard_external();
  } catch (...) {  // nothing may leave a destructor; what is left, the next run removes
  }
}

OutputDirectory::Writer OutputDirectory::open(const std::string& name) {
  auto state = std::make_unique<Writer::State>();
  state->owner = this;
  state->name = name;
  state->final_path = path_ / name;
  state->temporary = path_ / temporary_name(name);
  std::error_code ignored;
  fs::remove(state->temporary, ignored);  // never write through a link left under that name
  state->slot = register_temporary(state->temporary);
  errno = 0;
  state->out.open(state->temporary, std::ios::binary | std::ios::trunc);
  if (!state->out) {
    const int error = errno;
    unregister_temporary(state->slot);
    throw std::runtime_error("cannot write " + state->temporary.string() + ": " + reason(error));
  }
  return Writer(std::move(state));
}

void OutputDirectory::write(const std::string& name, std::string_view content) {
  Writer w = open(name);
  w.stream().write(content.data(), static_cast<std::streamsize>(content.size()));
  w.commit();
}

std::string OutputDirectory::external(const std::string& name) {
  const std::string temporary = temporary_name(name);
  std::error_code ignored;
  fs::remove(path_ / temporary, ignored);
  const bool known = std::any_of(external_.begin(), external_.end(),
                                 [&](const External& e) { return e.name == name; });
  if (!known) external_.push_back({name, register_temporary(path_ / temporary)});
  return temporary;
}

std::vector<std::string> OutputDirectory::commit_external() {
  std::vector<std::string> renamed;
  for (const External& e : external_) {
    const fs::path temporary = path_ / temporary_name(e.name);
    std::error_code ec;
    if (!fs::is_regular_file(temporary, ec)) continue;
    fs::rename(temporary, path_ / e.name, ec);
    if (ec) {
      throw std::runtime_error("cannot rename " + temporary.string() + " to " + e.name + ": " +
                               ec.message());
    }
    note_written(e.name);
    renamed.push_back(e.name);
  }
  discard_external();  // unregisters; the renamed ones are gone already
  return renamed;
}

void OutputDirectory::discard_external() {
  for (const External& e : external_) {
    std::error_code ignored;
    fs::remove(path_ / temporary_name(e.name), ignored);
    unregister_temporary(e.slot);
  }
  external_.clear();
}

void OutputDirectory::note_written(const std::string& name) {
  if (std::find(written_.begin(), written_.end(), name) == written_.end()) {
    written_.push_back(name);
  }
}

void OutputDirectory::remove_stale_files() {
  std::vector<fs::path> stale;
  std::error_code ec;
  for (fs::directory_iterator it(path_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::error_code type_error;
    if (!is_output_file_name(name) || it->is_directory(type_error)) continue;  // not ours
    if (std::find(written_.begin(), written_.end(), name) == written_.end()) {
      stale.push_back(it->path());
    }
  }
  if (ec) throw std::runtime_error("cannot list " + path_.string() + ": " + ec.message());
  for (const fs::path& p : stale) remove_file(p);
}

}  // namespace nlobs::cli
