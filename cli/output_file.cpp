#include "output_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "descriptor_buffer.hpp"
#include "nlobs/common/file_type.hpp"
#include "nlobs/solvers/status.hpp"

namespace nlobs::cli {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kTemporaryInfix = ".tmp-";
constexpr std::size_t kRandomLength = 6;  // mkostemp's XXXXXX
// A temporary's name must fit NAME_MAX (255) with the dot, the infix and the random part.
constexpr std::size_t kMaxNameInTemporary = 200;

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

std::string reason(int error) {
  return std::strerror(error != 0 ? error : EIO);
}

[[noreturn]] void fail(const std::string& what, const fs::path& p, int error) {
  throw std::runtime_error(what + " " + shown(p) + ": " + reason(error));
}

// The mode a new file gets from open(…, 0666): the process's umask applied. umask() can only be
// read by setting it, so it is read once, before any file is written.
mode_t new_file_mode() {
  static const mode_t mode = [] {
    const mode_t mask = ::umask(022);
    ::umask(mask);
    return static_cast<mode_t>(0666 & ~mask);
  }();
  return mode;
}

enum class Kind { kReplace, kInPlace, kStandardStream };

struct Target {
  Kind kind;
  fs::path file;  // the file replaced (a link's target) or written in place
  bool exists;
  struct stat status;
  int descriptor = -1;  // kStandardStream: STDOUT_FILENO or STDERR_FILENO
};

// STDOUT_FILENO or STDERR_FILENO when `st` is the file this process's standard output or error
// writes to (`--csv /dev/stdout > rows.csv`, or `--csv rows.csv > rows.csv`); else -1. Such a
// file is written through that descriptor: replacing it would leave the shell's redirection
// writing to an unlinked file and the user with half of the output.
int standard_stream_of(const struct stat& st) {
  for (const int fd : {STDOUT_FILENO, STDERR_FILENO}) {
    struct stat stream {};
    if (::fstat(fd, &stream) == 0 && stream.st_dev == st.st_dev && stream.st_ino == st.st_ino) {
      return fd;
    }
  }
  return -1;
}

// How `path` is written (output_file.hpp).
Target classify(const fs::path& path) {
  struct stat own {};
  if (::lstat(path.c_str(), &own) != 0) {
    if (errno == ENOENT) return {Kind::kReplace, path, false, {}};
    fail("cannot write", path, errno);
  }
  struct stat final = own;
  fs::path file = path;
  const bool link = S_ISLNK(own.st_mode);
  if (link) {
    if (::stat(path.c_str(), &final) != 0) {
      if (errno == ENOENT) {
        throw std::runtime_error("cannot write " + shown(path) +
                                 ": it is a symbolic link to a missing file (nlobs writes "
                                 "through a link only to an existing file)");
      }
      fail("cannot write", path, errno);
    }
  }
  if (!S_ISDIR(final.st_mode)) {
    if (const int fd = standard_stream_of(final); fd >= 0) {
      return {Kind::kStandardStream, path, true, final, fd};
    }
  }
  if (S_ISREG(final.st_mode)) {
    if (link) {
      std::error_code ec;
      file = fs::canonical(path, ec);
      if (ec) fail("cannot resolve the link", path, ec.value());
    }
    return {Kind::kReplace, file, true, final};
  }
  if (S_ISFIFO(final.st_mode) || S_ISCHR(final.st_mode)) {
    return {Kind::kInPlace, path, true, final};
  }
  throw std::runtime_error("cannot write " + shown(path) + ": it is " +
                           (link ? std::string("a symbolic link to ") : std::string()) +
                           file_type_name(final.st_mode) +
                           (S_ISDIR(final.st_mode) ? "" : ", not a file nlobs replaces"));
}

}  // namespace

void install_interrupt_cleanup() {
  (void)new_file_mode();  // read the umask now, not from a signal-sensitive place later
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

std::string shown(const fs::path& p) {
  return quoted_excerpt(p.native(), 300);
}

void set_interruptible_child(pid_t pid) {
  g_child.store(pid);
}

std::string_view final_name_of_temporary(std::string_view name) {
  const std::size_t infix = name.rfind(kTemporaryInfix);
  if (name.size() < 2 || name[0] != '.' || infix == std::string_view::npos || infix < 2 ||
      name.size() != infix + kTemporaryInfix.size() + kRandomLength) {
    return {};
  }
  return name.substr(1, infix - 1);
}

bool is_temporary_name_of(std::string_view name, std::string_view final_name) {
  const std::string_view stem = final_name.substr(0, kMaxNameInTemporary);
  return !stem.empty() && final_name_of_temporary(name) == stem;
}

// ---------------------------------------------------------------------------------------------

struct OutputFile::State {
  fs::path path;       // as given
  fs::path file;       // replaced or written in place
  fs::path temporary;  // empty when in place
  int fd = -1;
  int slot = -1;
  DescriptorBuffer buffer;
  std::ostream out{nullptr};

  ~State() {
    if (fd >= 0) ::close(fd);
    if (!temporary.empty()) ::unlink(temporary.c_str());
    unregister_temporary(slot);
  }
};

OutputFile::OutputFile(const fs::path& path) : state_(std::make_unique<State>()) {
  if (path.empty()) throw std::runtime_error("cannot write a file with an empty name");
  State& s = *state_;
  s.path = path;
  const Target target = classify(path);
  s.file = target.file;
  if (target.kind == Kind::kStandardStream) {
    // A duplicate shares the stream's file offset (and O_APPEND): the content lands after what
    // the process printed so far, as if printed itself. What std::cout holds goes first.
    std::cout.flush();
    std::cerr.flush();
    s.fd = ::fcntl(target.descriptor, F_DUPFD_CLOEXEC, 3);
    if (s.fd < 0) fail("cannot write", path, errno);
  } else if (target.kind == Kind::kInPlace) {
    // O_NONBLOCK: a FIFO with no reader fails at once (ENXIO) instead of blocking for ever;
    // blocking writes again afterwards. No O_TRUNC, no O_CREAT: nothing is replaced.
    s.fd = ::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC | O_NONBLOCK);
    if (s.fd < 0) {
      if (errno == ENXIO && S_ISFIFO(target.status.st_mode)) {
        throw std::runtime_error("cannot write " + shown(path) +
                                 ": it is a FIFO that no process is reading");
      }
      fail("cannot write", path, errno);
    }
    const int flags = ::fcntl(s.fd, F_GETFL);
    if (flags < 0 || ::fcntl(s.fd, F_SETFL, flags & ~O_NONBLOCK) < 0)
      fail("cannot write", path, errno);
  } else {
    const fs::path directory = s.file.has_parent_path() ? s.file.parent_path() : fs::path(".");
    const std::string stem = s.file.filename().string().substr(0, kMaxNameInTemporary);
    std::string pattern =
        (directory / ("." + stem + std::string(kTemporaryInfix) + "XXXXXX")).string();
    // mkostemp opens with O_CREAT | O_EXCL: a link or file already under the name is never
    // written through; the random part makes the name unpredictable.
    s.fd = ::mkostemp(pattern.data(), O_CLOEXEC);
    if (s.fd < 0) {
      const int error = errno;
      throw std::runtime_error("cannot write " + shown(path) + ": cannot create a file in " +
                               shown(directory) + ": " + reason(error));
    }
    s.temporary = pattern;
    s.slot = register_temporary(s.temporary);
    const mode_t mode = target.exists ? (target.status.st_mode & 07777) : new_file_mode();
    if (target.exists && ::geteuid() == 0) {
      // root replacing a user's file gives it back to the user (best effort, as cp -p).
      (void)!::fchown(s.fd, target.status.st_uid, target.status.st_gid);
    }
    if (::fchmod(s.fd, mode) != 0) fail("cannot set the permissions of", s.temporary, errno);
  }
  s.buffer.attach(s.fd);
  s.out.rdbuf(&s.buffer);
}

OutputFile::~OutputFile() = default;
OutputFile::OutputFile(OutputFile&&) noexcept = default;

std::ostream& OutputFile::stream() {
  return state_->out;
}

int OutputFile::descriptor() const {
  return state_->fd;
}

const fs::path& OutputFile::temporary() const {
  return state_->temporary;
}

const fs::path& OutputFile::path() const {
  return state_->path;
}

bool OutputFile::empty() const {
  if (state_->buffer.written()) return false;
  struct stat st {};
  return ::fstat(state_->fd, &st) != 0 || st.st_size == 0;
}

void OutputFile::commit() {
  State& s = *state_;
  const fs::path& written = s.temporary.empty() ? s.path : s.temporary;
  if (s.temporary.empty()) std::cout.flush();  // in place: what was printed before comes first
  s.out.flush();
  if (!s.buffer.drain()) fail("writing", written, s.buffer.error());
  if (!s.temporary.empty() && ::fsync(s.fd) != 0) fail("writing", written, errno);
  const int fd = s.fd;
  s.fd = -1;
  if (::close(fd) != 0 && errno != EINTR) fail("writing", written, errno);
  if (!s.temporary.empty()) {
    if (::rename(s.temporary.c_str(), s.file.c_str()) != 0) {
      const int error = errno;
      throw std::runtime_error("cannot rename " + shown(s.temporary) + " to " + shown(s.file) +
                               ": " + reason(error));
    }
    s.temporary.clear();  // renamed: nothing to remove
  }
  state_.reset();
}

void write_output_file(const fs::path& path, std::string_view content) {
  OutputFile file(path);
  file.stream().write(content.data(), static_cast<std::streamsize>(content.size()));
  file.commit();
}

}  // namespace nlobs::cli
