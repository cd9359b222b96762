#include "gnuplot.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "run_support.hpp"

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

std::string run_gnuplot_script(const std::filesystem::path& dir, const std::string& script_name,
                               const std::string& script) {
  const std::optional<std::filesystem::path> gnuplot = find_gnuplot();
  if (!gnuplot) return "gnuplot not found on PATH";
  try {
    write_atomically(dir / script_name, script);
  } catch (const std::exception& e) {
    return e.what();
  }
  // The log is opened here, so that a failure names it rather than gnuplot.
  const std::filesystem::path log_path = dir / "gnuplot.log";
  const int log =
      ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (log < 0) return "cannot write " + log_path.string() + ": " + std::strerror(errno);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // The child starts in dir (no "cd" through a shell), stdin and stdout on /dev/null, stderr
  // in gnuplot.log.
  int setup = posix_spawn_file_actions_addchdir_np(&actions, dir.c_str());
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
  ::close(log);
  if (spawned != 0) {
    return "cannot start " + program + " in " + dir.string() + ": " + std::strerror(spawned);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return std::string("waiting for gnuplot: ") + std::strerror(errno);
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
  return "gnuplot failed (" + first + "; see " + (dir / "gnuplot.log").string() + ")";
}

}  // namespace nlobs::cli
