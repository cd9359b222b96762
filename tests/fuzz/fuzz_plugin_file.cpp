// libFuzzer target: the plugin loader's checks on a file's bytes (registry/src/plugin_file.hpp)
// before dlopen, on arbitrary bytes as a whole file. Either the file is refused with a reason,
// or it is accepted and the promises dlopen relies on hold: a complete ELF header of this
// build's class, byte order and type, every program header and section within the file. A
// crash, a sanitizer report (a read past the bytes given), an empty or unprintable reason, or
// an accepted file that breaks a promise is a finding. `make fuzz` runs it; docs/fuzzing.md.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "plugin_file.hpp"

namespace {

void check(bool invariant) {
  if (!invariant) std::abort();
}

template <typename T>
T at(std::string_view file, std::uint64_t offset) {
  T value;
  std::memcpy(&value, file.data() + offset, sizeof(T));
  return value;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  using namespace nlobs::plugin_file;
  const std::string_view file(reinterpret_cast<const char*>(bytes), size);
  const std::string problem = elf_problem(file);
  if (!problem.empty()) {
    // A reason the loader prints after "it ": plain ASCII, no control character, bounded.
    check(problem.size() < 200);
    for (const char c : problem) check(c >= 0x20 && c < 0x7F);
    return 0;
  }
  // Accepted: re-check what dlopen relies on, independently of the checker's own code paths.
  using detail::Ehdr, detail::Phdr, detail::Shdr;
  check(size >= sizeof(Ehdr) && std::memcmp(bytes, ELFMAG, SELFMAG) == 0);
  const auto header = at<Ehdr>(file, 0);
  check(header.e_ident[EI_CLASS] == detail::kHostClass &&
        header.e_ident[EI_DATA] == detail::kHostData && header.e_type == ET_DYN);
  if (header.e_phnum > 0 && header.e_phnum != PN_XNUM) {
    check(header.e_phoff <= size && header.e_phnum * sizeof(Phdr) <= size - header.e_phoff);
    for (std::size_t i = 0; i < header.e_phnum; ++i) {
      const auto segment = at<Phdr>(file, header.e_phoff + i * sizeof(Phdr));
      check(segment.p_offset <= size && segment.p_filesz <= size - segment.p_offset);
    }
  }
  if (header.e_shnum > 0) {
    check(header.e_shoff <= size && header.e_shnum * sizeof(Shdr) <= size - header.e_shoff);
  }
  return 0;
}
