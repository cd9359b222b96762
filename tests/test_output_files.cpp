// The one way the CLI writes a file (cli/output_file.hpp, docs/cli.md "Output files"): what a
// path holds decides how, and nothing that is not a regular file is ever replaced by one — a
// link, a FIFO, a device (as root, `--csv /dev/null` used to replace the device node), a
// directory; temporaries are unpredictable and created exclusively; a failed write keeps the
// earlier file and says the system's reason; an output directory is locked against a second run.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "cli_test_files.hpp"
#include "output_directory.hpp"
#include "output_file.hpp"

namespace nlobs::cli {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path p = test::scratch_path("nlobs_test_output_files", name);
  fs::remove_all(p);
  return p;
}

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The error OutputFile's constructor or commit throws for `path`, or "" when none.
std::string error_writing(const fs::path& path, const std::string& content) {
  try {
    write_output_file(path, content);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::size_t entries(const fs::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

TEST(OutputFile, ANewFileGetsTheUmasksMode) {
  const fs::path dir = scratch("new");
  fs::create_directories(dir);
  const mode_t mask = ::umask(027);
  write_output_file(dir / "rows.csv", "a,b\n");
  ::umask(mask);
  EXPECT_EQ(read(dir / "rows.csv"), "a,b\n");
  struct stat st {};
  ASSERT_EQ(::stat((dir / "rows.csv").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0640U);
  EXPECT_EQ(entries(dir), 1U);  // no temporary left
}

TEST(OutputFile, AReplacedFileKeepsItsModeAndIsReplacedWhole) {
  const fs::path dir = scratch("replace");
  fs::create_directories(dir);
  test::write_file(dir / "rows.csv", "old");
  ASSERT_EQ(::chmod((dir / "rows.csv").c_str(), 0600), 0);
  struct stat before {};
  ASSERT_EQ(::stat((dir / "rows.csv").c_str(), &before), 0);
  OutputFile file(dir / "rows.csv");
  file.stream() << "new";
  // Until the commit the file is the earlier one, and the temporary is not a predictable name.
  EXPECT_EQ(read(dir / "rows.csv"), "old");
  const std::string temporary = file.temporary().filename().string();
  EXPECT_TRUE(is_temporary_name_of(temporary, "rows.csv")) << temporary;
  EXPECT_NE(temporary, "rows.csv.tmp-nlobs");
  file.commit();
  EXPECT_EQ(read(dir / "rows.csv"), "new");
  struct stat after {};
  ASSERT_EQ(::stat((dir / "rows.csv").c_str(), &after), 0);
  EXPECT_EQ(after.st_mode & 07777, 0600U);
  EXPECT_NE(after.st_ino, before.st_ino);  // renamed into place, not rewritten in place
  EXPECT_EQ(entries(dir), 1U);
}

// The earlier `--csv` wrote PATH.tmp-nlobs through whatever was there: a link planted under that
// name overwrote its target.
TEST(OutputFile, ALinkPlantedUnderTheOldTemporaryNameIsNotWrittenThrough) {
  const fs::path dir = scratch("planted");
  fs::create_directories(dir);
  test::write_file(dir / "victim", "precious");
  fs::create_symlink(dir / "victim", dir / "rows.csv.tmp-nlobs");
  write_output_file(dir / "rows.csv", "rows");
  EXPECT_EQ(read(dir / "victim"), "precious");
  EXPECT_EQ(read(dir / "rows.csv"), "rows");
  EXPECT_TRUE(fs::is_symlink(dir / "rows.csv.tmp-nlobs"));
}

TEST(OutputFile, ALinkToAFileReplacesTheFileAndStaysALink) {
  const fs::path dir = scratch("link");
  fs::create_directories(dir / "results");
  test::write_file(dir / "results" / "run1.csv", "old");
  fs::create_symlink(dir / "results" / "run1.csv", dir / "latest.csv");
  write_output_file(dir / "latest.csv", "new");
  EXPECT_TRUE(fs::is_symlink(dir / "latest.csv"));
  EXPECT_EQ(read(dir / "results" / "run1.csv"), "new");
  EXPECT_EQ(entries(dir / "results"), 1U);  // the temporary was beside the target
}

TEST(OutputFile, ADanglingLinkOrALinkToADirectoryIsRefusedAndKept) {
  const fs::path dir = scratch("dangling");
  fs::create_directories(dir / "sub");
  fs::create_symlink(dir / "missing", dir / "to-nothing.csv");
  fs::create_symlink(dir / "sub", dir / "to-dir.csv");
  const std::string nothing = error_writing(dir / "to-nothing.csv", "x");
  EXPECT_TRUE(contains(nothing, "to-nothing.csv': it is a symbolic link to a missing file"))
      << nothing;
  const std::string directory = error_writing(dir / "to-dir.csv", "x");
  EXPECT_TRUE(contains(directory, "it is a symbolic link to a directory")) << directory;
  EXPECT_TRUE(fs::is_symlink(dir / "to-nothing.csv"));
  EXPECT_TRUE(fs::is_symlink(dir / "to-dir.csv"));
  EXPECT_FALSE(fs::exists(dir / "missing"));
  EXPECT_EQ(entries(dir), 3U);
  EXPECT_TRUE(contains(error_writing(dir / "sub", "x"), "it is a directory"));
}

TEST(OutputFile, AFifoIsWrittenInPlaceOrRefusedWhenNobodyReads) {
  const fs::path dir = scratch("fifo");
  fs::create_directories(dir);
  const fs::path fifo = dir / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // No reader: refused at once (it used to block for ever, or be replaced by a file).
  const std::string refused = error_writing(fifo, "rows");
  EXPECT_TRUE(contains(refused, "it is a FIFO that no process is reading")) << refused;
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  write_output_file(fifo, "rows\n");
  char buffer[16] = {};
  EXPECT_EQ(::read(reader, buffer, sizeof buffer), 5);
  EXPECT_EQ(std::string(buffer), "rows\n");
  ::close(reader);
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(entries(dir), 1U);
}

TEST(OutputFile, DevicesAreWrittenNotReplaced) {
  write_output_file("/dev/null", "discarded");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  const std::string full = error_writing("/dev/full", std::string(200000, 'x'));
  EXPECT_TRUE(contains(full, "writing '/dev/full': No space left on device")) << full;
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
}

// `--csv /dev/stdout > rows.csv` (or `--csv rows.csv > rows.csv`): the file the shell redirected
// standard output to is written through that descriptor, after what was printed, and keeps its
// inode; replacing it left the table in an unlinked file and rows.csv holding the CSV alone.
TEST(OutputFile, TheFileStandardOutputWritesToIsAppendedToNotReplaced) {
  const fs::path dir = scratch("stdout");
  fs::create_directories(dir);
  const fs::path file = dir / "rows.csv";
  for (const fs::path& name : {fs::path("/dev/stdout"), file}) {
    std::cout.flush();
    const int saved = ::dup(STDOUT_FILENO);
    ASSERT_GE(saved, 0);
    const int redirected = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(redirected, 0);
    struct stat before {};
    ASSERT_EQ(::fstat(redirected, &before), 0);
    ASSERT_GE(::dup2(redirected, STDOUT_FILENO), 0);
    ::close(redirected);
    std::cout << "table\n";
    const std::string error = error_writing(name, "rows\n");
    std::cout << "footer\n";
    std::cout.flush();
    ::dup2(saved, STDOUT_FILENO);
    ::close(saved);
    EXPECT_EQ(error, "") << name;
    struct stat after {};
    ASSERT_EQ(::stat(file.c_str(), &after), 0);
    EXPECT_EQ(after.st_ino, before.st_ino) << name;
    EXPECT_EQ(read(file), "table\nrows\nfooter\n") << name;
    EXPECT_EQ(entries(dir), 1U) << name;
  }
}

// A disk that fills up (here: a file size limit) fails the commit with the system's reason and
// keeps the earlier file whole.
TEST(OutputFile, AFailedWriteKeepsTheEarlierFileAndLeavesNoTemporary) {
  const fs::path dir = scratch("full");
  fs::create_directories(dir);
  test::write_file(dir / "rows.csv", "earlier");
  struct rlimit saved {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
  struct sigaction ignore {
  }, previous{};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGXFSZ, &ignore, &previous);
  struct rlimit small = saved;
  small.rlim_cur = 4096;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  const std::string error = error_writing(dir / "rows.csv", std::string(100000, 'x'));
  ::setrlimit(RLIMIT_FSIZE, &saved);
  ::sigaction(SIGXFSZ, &previous, nullptr);
  EXPECT_TRUE(contains(error, "File too large")) << error;
  EXPECT_EQ(read(dir / "rows.csv"), "earlier");
  EXPECT_EQ(entries(dir), 1U);
}

TEST(OutputFile, AnUncommittedFileLeavesNothing) {
  const fs::path dir = scratch("dropped");
  fs::create_directories(dir);
  {
    OutputFile file(dir / "rows.csv");
    file.stream() << "half";
    EXPECT_TRUE(fs::exists(file.temporary()));
  }
  EXPECT_EQ(entries(dir), 0U);
}

TEST(OutputFile, TemporaryNames) {
  EXPECT_EQ(final_name_of_temporary(".summary.json.tmp-a1B2c3"), "summary.json");
  EXPECT_TRUE(is_temporary_name_of(".summary.json.tmp-a1B2c3", "summary.json"));
  EXPECT_FALSE(is_temporary_name_of(".summary.json.tmp-a1B2c", "summary.json"));
  EXPECT_FALSE(is_temporary_name_of("summary.json.tmp-a1B2c3", "summary.json"));
  EXPECT_EQ(final_name_of_temporary("notes.txt"), "");
  EXPECT_EQ(final_name_of_temporary(".tmp-abcdef"), "");
}

// Two runs into one --out used to mix their files silently.
TEST(OutputDirectoryLock, ASecondRunIntoTheSameDirectoryFailsByName) {
  const fs::path dir = scratch("locked");
  fs::create_directories(dir);
  {
    // Another process's lock, as its flock on its own open file: a second open file
    // description here conflicts the same way.
    const int other = ::open((dir / ".nlobs.lock").c_str(), O_RDWR | O_CREAT, 0644);
    ASSERT_GE(other, 0);
    ASSERT_EQ(::flock(other, LOCK_EX | LOCK_NB), 0);
    ASSERT_EQ(::write(other, "4242\n", 5), 5);
    try {
      OutputDirectory out(dir.string());
      ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
      EXPECT_TRUE(contains(e.what(), "another nlobs run (pid 4242) is writing into")) << e.what();
    }
    ::close(other);
  }
  {
    // Released: the run takes it, and this process's directory objects share it.
    const OutputDirectoryLock held(dir.string());
    OutputDirectory out(dir.string());
    out.write("summary.json", "{}");
    EXPECT_TRUE(fs::exists(dir / ".nlobs.lock"));
  }
  EXPECT_FALSE(fs::exists(dir / ".nlobs.lock"));  // removed with the last holder
  EXPECT_EQ(read(dir / "summary.json"), "{}");
}

TEST(OutputDirectoryLock, ALinkOrFifoUnderTheLockNameIsRefused) {
  const fs::path dir = scratch("lock-link");
  fs::create_directories(dir);
  test::write_file(dir / "victim", "precious");
  fs::create_symlink(dir / "victim", dir / ".nlobs.lock");
  try {
    OutputDirectory out(dir.string());
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_TRUE(contains(e.what(), "it is a symbolic link")) << e.what();
  }
  EXPECT_EQ(read(dir / "victim"), "precious");
  fs::remove(dir / ".nlobs.lock");
  ASSERT_EQ(::mkfifo((dir / ".nlobs.lock").c_str(), 0600), 0);
  try {
    OutputDirectory out(dir.string());
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_TRUE(contains(e.what(), "is not a regular file")) << e.what();
  }
}

// A FIFO or a link under an nlobs name in --out is the user's: not removed as stale, not
// replaced by a regular file.
TEST(OutputDirectory, NonRegularFilesUnderNlobsNamesAreNeverReplaced) {
  const fs::path dir = scratch("special");
  fs::create_directories(dir);
  ASSERT_EQ(::mkfifo((dir / "sweep.csv").c_str(), 0600), 0);
  test::write_file(dir / "elsewhere.json", "kept");
  fs::create_symlink(dir / "elsewhere.json", dir / "summary.json");
  {
    OutputDirectory out(dir.string());
    out.remove_stale_files();
  }
  EXPECT_TRUE(fs::is_fifo(dir / "sweep.csv"));
  EXPECT_TRUE(fs::is_symlink(dir / "summary.json"));
  EXPECT_EQ(read(dir / "elsewhere.json"), "kept");
  {
    OutputDirectory out(dir.string());
    out.write("summary.json", "{}");  // through the link, into its target
  }
  EXPECT_TRUE(fs::is_symlink(dir / "summary.json"));
  EXPECT_EQ(read(dir / "elsewhere.json"), "{}");
}

}  // namespace
}  // namespace nlobs::cli
