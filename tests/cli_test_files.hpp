#pragma once
// Files for the CLI tests: a scratch directory per test program and process, files written
// whole, a fake program put first on PATH (a gnuplot that fails, hangs or is killed), and a
// command run through the shell with its output and exit status.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace nlobs::test {

struct CliRun {
  int status = -1;  // the exit status; -1 when it did not exit normally
  std::string out;  // stdout and stderr
};

// Runs `command` (test-made text only: it goes to the shell) with stderr joined to stdout.
inline CliRun run_shell_command(const std::string& command) {
  CliRun r;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.out.append(buf.data(), n);
  const int rc = pclose(pipe);
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  return r;
}

// temp/PREFIX_PID/NAME, its parent created.
inline std::filesystem::path scratch_path(const std::string& prefix, const std::string& name) {
  const std::filesystem::path p =
      std::filesystem::temp_directory_path() / (prefix + "_" + std::to_string(::getpid())) / name;
  std::filesystem::create_directories(p.parent_path());
  return p;
}

inline void write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// While alive, PATH is `bin` alone, holding an executable `program` with the shell `script`.
class FakeProgramOnPath {
 public:
  FakeProgramOnPath(const std::filesystem::path& bin, const std::string& program,
                    const std::string& script) {
    std::filesystem::create_directories(bin);
    write_file(bin / program, script);
    std::filesystem::permissions(bin / program, std::filesystem::perms::owner_all);
    const char* old = std::getenv("PATH");
    saved_ = old != nullptr ? old : "";
    ::setenv("PATH", bin.c_str(), 1);
  }
  ~FakeProgramOnPath() { ::setenv("PATH", saved_.c_str(), 1); }
  FakeProgramOnPath(const FakeProgramOnPath&) = delete;
  FakeProgramOnPath& operator=(const FakeProgramOnPath&) = delete;

 private:
  std::string saved_;
};

}  // namespace nlobs::test
