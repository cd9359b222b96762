#include "gnuplot.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "output_directory.hpp"
#include "output_file.hpp"

extern char** environ;

namespace nlobs::cli {

std::string gnuplot_quoted(std::string_view text) {
  std::string out = "'";
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\'') {
      out += "''";
    } else if (u < 0x20 || u == 0x7f) {
      if (c == '\n') {
        out += "\\n";
      } else if (c == '\r') {
        out += "\\r";
      } else if (c == '\t') {
        out += "\\t";
      } else {
        char buf[8];
        std::snprintf(buf, sizeof buf, "\\x%02x", u);
        out += buf;
      }
    } else {
      out += c;
    }
  }
  return out + "'";
}

std::string gnuplot_data_token(std::string_view text) {
  std::string out;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    out += (u <= 0x20 || u == 0x7f || c == '#') ? '_' : c;
  }
  return out.empty() ? "_" : out;
}

std::string gnuplot_comment_text(std::string_view text) {
  const std::string quoted = gnuplot_quoted(text);  // control characters made visible
  return quoted.substr(1, quoted.size() - 2);
}

std::optional<std::filesystem::path> find_gnuplot() {
  const char* path = std::getenv("PATH");
  const std::string dirs = path != nullptr ? path : "/usr/bin:/bin";
  size_t start = 0;
  while (start <= dirs.size()) {
    const size_t colon = dirs.find(':', start);
    const std::string dir =
        dirs.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    // Absolute entries only: gnuplot runs in the output directory, where a relative entry (or
    // the empty one, ".") would name another file.
    const std::filesystem::path candidate = std::filesystem::path(dir) / "gnuplot";
    if (candidate.is_absolute() && ::access(candidate.c_str(), X_OK) == 0 &&
        !std::filesystem::is_directory(candidate)) {
      return candidate;
    }
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  return std::nullopt;
}

std::string run_gnuplot_script(OutputDirectory& dir, const std::string& script_name,
                               const std::string& script, std::chrono::milliseconds timeout) {
  const std::optional<std::filesystem::path> gnuplot = find_gnuplot();
  if (!gnuplot) return "gnuplot not found on PATH";
  try {
    dir.write(script_name, script);
  } catch (const std::exception& e) {
    return e.what();
  }
  // The log is opened here, so that a failure names it rather than gnuplot; like every output
  // file it is written under a temporary name and renamed when gnuplot is done.
  const std::filesystem::path log_path = dir.path() / "gnuplot.log";
  std::optional<OutputFile> log_file;
  try {
    log_file.emplace(log_path);
  } catch (const std::exception& e) {
    return e.what();
  }
  const int log = log_file->descriptor();
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // The child starts in dir (no "cd" through a shell), stdin and stdout on /dev/null, stderr
  // in gnuplot.log.
  int setup = posix_spawn_file_actions_addchdir_np(&actions, dir.path().c_str());
  if (setup == 0) setup = posix_spawn_file_actions_adddup2(&actions, log, STDERR_FILENO);
  if (setup == 0) {
    setup = posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  }
  if (setup == 0) {
    setup = posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  }
  std::string program = gnuplot->string(), name = script_name;
  std::vector<char*> argv = {program.data(), name.data(), nullptr};
  pid_t pid = 0;
  const int spawned =
      setup != 0 ? setup
                 : posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    return "cannot start " + program + " in " + dir.path().string() + ": " + std::strerror(spawned);
  }
  // Polled, so that a gnuplot that hangs (a huge plot, a stuck font lookup) is stopped. The
  // child is reaped only after the signal handler has forgotten it (waitid with WNOWAIT leaves
  // it a zombie), so the handler can never kill a process that reuses its PID.
  set_interruptible_child(pid);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  bool timed_out = false;
  for (;;) {
    siginfo_t info{};
    const int polled = waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT);
    if (polled == 0 && info.si_pid == pid) break;  // exited, not yet reaped
    if (polled < 0 && errno != EINTR) {
      const int error = errno;
      set_interruptible_child(0);
      return std::string("waiting for gnuplot: ") + std::strerror(error);
    }
    if (!timed_out && std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      timed_out = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  set_interruptible_child(0);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  try {
    log_file->commit();
    dir.note_written("gnuplot.log");
  } catch (const std::exception& e) {
    return e.what();
  }
  if (timed_out) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g s", static_cast<double>(timeout.count()) / 1e3);
    return std::string("gnuplot did not finish within ") + limit + " and was stopped (see " +
           log_path.string() + ")";
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return {};
  // gnuplot echoes the failing command, marks the column with ^, then says
  // "plots.gp" line 12: what went wrong — that line is the reason; else the first non-blank one.
  std::ifstream log_text(log_path);
  std::string line, first;
  const std::string located = "\"" + script_name + "\" line ";
  while (std::getline(log_text, line)) {
    if (line.find("warning:") != std::string::npos) continue;  // e.g. "skipping data file"
    if (line.find(located) != std::string::npos) {
      first = line;
      break;
    }
    if (first.empty() && line.find_first_not_of(" \t^") != std::string::npos) first = line;
  }
  if (first.empty()) {
    first = WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                : "exit status " + std::to_string(WEXITSTATUS(status));
  }
  return "gnuplot failed (" + first + "; see " + log_path.string() + ")";
}

}  // namespace nlobs::cli
