#include "output_directory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>
#include <stdexcept>
#include <system_error>

#include "nlobs/solvers/status.hpp"

namespace nlobs::cli {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kOldTemporarySuffix = ".tmp";  // before OutputFile's random names

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

bool is_final_output_name(std::string_view name) {
  const auto& names = output_file_names();
  return is_signals_png(name) || std::find(names.begin(), names.end(), name) != names.end();
}

// Removes a regular file of that name; anything else under it (a directory, a link, a FIFO) is
// the user's and stays.
void remove_regular_file(const fs::path& p) {
  struct stat st {};
  if (::lstat(p.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return;
  if (::unlink(p.c_str()) != 0 && errno != ENOENT) {
    const int error = errno;
    throw std::runtime_error("cannot remove " + shown(p) + ": " + std::strerror(error));
  }
}

// The directory locks this process holds, by path: run_scenario() locks its --out directory
// before it computes, the OutputDirectory it then opens shares that lock (a second flock of the
// same file from this process would refuse it).
struct HeldLock {
  int fd = -1;
  fs::path file;
  ~HeldLock() {
    // Removed while still held, so that no later run takes a lock on an unlinked file (the
    // taker checks the path still names its file).
    ::unlink(file.c_str());
    ::close(fd);
  }
};
std::mutex g_locks_mutex;
std::map<fs::path, std::weak_ptr<HeldLock>> g_locks;

std::shared_ptr<HeldLock> take_lock(const fs::path& directory) {
  const std::lock_guard<std::mutex> guard(g_locks_mutex);
  if (auto held = g_locks[directory].lock()) return held;
  const fs::path file = directory / kOutputLockName;
  for (int attempt = 0; attempt < 8; ++attempt) {
    // O_NOFOLLOW | O_NONBLOCK: a link or a FIFO planted under the name is neither followed nor
    // waited on; it is refused below.
    const int fd =
        ::open(file.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
    if (fd < 0) {
      const int error = errno;
      throw std::runtime_error("cannot lock the output directory " + shown(directory) + ": " +
                               shown(file) + ": " +
                               (error == ELOOP ? "it is a symbolic link" : std::strerror(error)));
    }
    struct stat own {};
    if (::fstat(fd, &own) != 0 || !S_ISREG(own.st_mode)) {
      ::close(fd);
      throw std::runtime_error("cannot lock the output directory " + shown(directory) + ": " +
                               shown(file) + " is not a regular file");
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      char text[32] = {};
      const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
      ::close(fd);
      if (error != EWOULDBLOCK) {
        throw std::runtime_error("cannot lock the output directory " + shown(directory) + ": " +
                                 std::strerror(error));
      }
      std::string pid(text, n > 0 ? static_cast<std::size_t>(n) : 0);
      pid.erase(std::remove_if(pid.begin(), pid.end(), [](char c) { return c < '0' || c > '9'; }),
                pid.end());
      throw std::runtime_error("another nlobs run" + (pid.empty() ? "" : " (pid " + pid + ")") +
                               " is writing into " + shown(directory) +
                               "; two runs cannot share an output directory");
    }
    struct stat by_name {};
    if (::stat(file.c_str(), &by_name) == 0 && by_name.st_ino == own.st_ino &&
        by_name.st_dev == own.st_dev) {
      const std::string pid = std::to_string(::getpid()) + "\n";
      if (::ftruncate(fd, 0) == 0) (void)!::pwrite(fd, pid.data(), pid.size(), 0);
      auto held = std::make_shared<HeldLock>();
      held->fd = fd;
      held->file = file;
      g_locks[directory] = held;
      return held;
    }
    ::close(fd);  // the holder removed the file between our open and our flock: try again
  }
  throw std::runtime_error("cannot lock the output directory " + shown(directory) +
                           ": its lock file keeps changing");
}

fs::path create_output_directory(const std::string& path) {
  if (path.empty()) throw std::runtime_error("the output directory has an empty name");
  const fs::path absolute = fs::absolute(path);
  std::error_code ec;
  fs::create_directories(absolute, ec);
  if (ec) throw std::runtime_error("cannot create " + shown(absolute) + ": " + ec.message());
  if (!fs::is_directory(absolute)) {
    throw std::runtime_error("cannot write into " + shown(absolute) + ": not a directory");
  }
  return absolute;
}

}  // namespace

OutputDirectoryLock::OutputDirectoryLock(const std::string& path)
    : lock_(take_lock(create_output_directory(path))) {}
OutputDirectoryLock::~OutputDirectoryLock() = default;

const std::vector<std::string>& output_file_names() {
  static const std::vector<std::string> names = {
      "summary.json",  "trajectories.csv", "plot_data.csv", "first_window.dat",
      "scenario.json", "plots.gp",         "gnuplot.log",   "states.png",
      "errors.png",    "z_error.png",      "eta_error.png", "first_window.png",
      "sweep.csv",     "sweep.dat",        "sweep.gp",      "sweep.png"};
  return names;
}

bool is_output_file_name(std::string_view name) {
  if (const std::string_view final_name = final_name_of_temporary(name); !final_name.empty()) {
    return is_final_output_name(final_name);
  }
  if (name.ends_with(kOldTemporarySuffix)) name.remove_suffix(kOldTemporarySuffix.size());
  return is_final_output_name(name);
}

// ---------------------------------------------------------------------------------------------

OutputDirectory::Writer::Writer(OutputDirectory& owner, std::string name)
    : owner_(&owner), name_(std::move(name)), file_(owner.path() / name_) {}

void OutputDirectory::Writer::commit() {
  file_.commit();
  owner_->note_written(name_);
}

// ---------------------------------------------------------------------------------------------

OutputDirectory::OutputDirectory(const std::string& path)
    : path_(create_output_directory(path)), lock_(take_lock(path_)) {
  // From here on the directory is incomplete until its marker is written again.
  remove_regular_file(path_ / "summary.json");
  remove_regular_file(path_ / "sweep.csv");
  // Temporaries a killed run left (the lock says no run is writing here now).
  std::error_code ec;
  for (fs::directory_iterator it(path_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const bool temporary = !final_name_of_temporary(name).empty() ||
                           std::string_view(name).ends_with(kOldTemporarySuffix);
    if (temporary && is_output_file_name(name)) remove_regular_file(it->path());
  }
}

OutputDirectory::~OutputDirectory() = default;  // the OutputFiles remove their temporaries

OutputDirectory::Writer OutputDirectory::open(const std::string& name) {
  return Writer(*this, name);
}

void OutputDirectory::write(const std::string& name, std::string_view content) {
  Writer w = open(name);
  w.stream().write(content.data(), static_cast<std::streamsize>(content.size()));
  w.commit();
}

std::string OutputDirectory::external(const std::string& name) {
  for (const External& e : external_) {
    if (e.name == name) return e.file.temporary().filename().string();
  }
  external_.push_back({name, OutputFile(path_ / name)});
  const fs::path& temporary = external_.back().file.temporary();
  if (temporary.empty() || temporary.parent_path() != path_) {
    // A FIFO or device under the name, or a link out of the directory: gnuplot cannot be given
    // a name relative to DIR for it.
    external_.pop_back();
    throw std::runtime_error("cannot plot into " + shown(path_ / name) +
                             ": it is not a regular file in the output directory");
  }
  return temporary.filename().string();
}

std::vector<std::string> OutputDirectory::commit_external() {
  std::vector<std::string> renamed;
  for (External& e : external_) {
    if (e.file.empty()) continue;  // gnuplot wrote nothing there: discarded below
    e.file.commit();
    note_written(e.name);
    renamed.push_back(e.name);
  }
  external_.clear();  // the uncommitted ones remove their temporaries
  return renamed;
}

void OutputDirectory::discard_external() {
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
    if (!is_output_file_name(name)) continue;  // not ours
    if (std::find(written_.begin(), written_.end(), name) == written_.end()) {
      stale.push_back(it->path());
    }
  }
  if (ec) throw std::runtime_error("cannot list " + shown(path_) + ": " + ec.message());
  for (const fs::path& p : stale) remove_regular_file(p);
}

}  // namespace nlobs::cli
