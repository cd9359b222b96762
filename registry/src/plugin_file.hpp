#pragma once
// The checks the plugin loader makes on a file's bytes before it hands the file to dlopen.
// dlopen maps a library's segments as its program headers describe them and touches them while
// it relocates: a segment that ends past the end of the file (an interrupted copy) is a page
// with no file behind it, and touching it kills the process with SIGBUS instead of failing.
// So the headers are read first, and a library is refused by name unless it is an ELF shared
// object of this host's class, byte order and machine whose every program header, section and
// section header table lies within the file.
//
// These checks catch a damaged or wrong file (truncated, not ELF, 32-bit, another machine, an
// executable); they do not make a crafted file safe to load: a plugin is code that runs in the
// nlobs process (docs/extending.md, "What nlobs survives and what it cannot").
//
// Header-only and free of I/O so that the fuzz target fuzz_plugin_file (tests/fuzz) feeds it
// arbitrary bytes through elf_problem(std::string_view) with coverage instrumentation.
#include <elf.h>

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <string_view>
#include <type_traits>

namespace nlobs::plugin_file {

// Reads `count` bytes at `offset` into `out`; false when they cannot all be read.
using ReadAt = std::function<bool(std::uint64_t offset, std::size_t count, void* out)>;

namespace detail {

// This build's ELF flavour: a plugin must match it for dlopen to load it.
inline constexpr bool kHost64 = sizeof(void*) == 8;
using Ehdr = std::conditional_t<kHost64, Elf64_Ehdr, Elf32_Ehdr>;
using Phdr = std::conditional_t<kHost64, Elf64_Phdr, Elf32_Phdr>;
using Shdr = std::conditional_t<kHost64, Elf64_Shdr, Elf32_Shdr>;
inline constexpr unsigned char kHostClass = kHost64 ? ELFCLASS64 : ELFCLASS32;
inline constexpr unsigned char kHostData =
    std::endian::native == std::endian::little ? ELFDATA2LSB : ELFDATA2MSB;
#if defined(__x86_64__)
inline constexpr std::uint16_t kHostMachine = EM_X86_64;
#elif defined(__aarch64__)
inline constexpr std::uint16_t kHostMachine = EM_AARCH64;
#elif defined(__i386__)
inline constexpr std::uint16_t kHostMachine = EM_386;
#elif defined(__arm__)
inline constexpr std::uint16_t kHostMachine = EM_ARM;
#elif defined(__riscv)
inline constexpr std::uint16_t kHostMachine = EM_RISCV;
#elif defined(__powerpc64__)
inline constexpr std::uint16_t kHostMachine = EM_PPC64;
#elif defined(__powerpc__)
inline constexpr std::uint16_t kHostMachine = EM_PPC;
#elif defined(__s390x__)
inline constexpr std::uint16_t kHostMachine = EM_S390;
#else
inline constexpr std::uint16_t kHostMachine = EM_NONE;  // unknown here: not checked
#endif

inline std::string machine_name(std::uint16_t machine) {
  switch (machine) {
    case EM_X86_64:
      return "x86-64";
    case EM_AARCH64:
      return "AArch64";
    case EM_386:
      return "i386";
    case EM_ARM:
      return "32-bit ARM";
    case EM_RISCV:
      return "RISC-V";
    case EM_PPC64:
      return "PowerPC 64";
    case EM_PPC:
      return "PowerPC";
    case EM_S390:
      return "s390";
    default:
      return "e_machine " + std::to_string(machine);
  }
}

inline std::string type_name(std::uint16_t type) {
  switch (type) {
    case ET_NONE:
      return "it has no ELF type";
    case ET_REL:
      return "it is a relocatable object (a .o file)";
    case ET_EXEC:
      return "it is an executable";
    case ET_CORE:
      return "it is a core dump";
    default:
      return "its ELF type is " + std::to_string(type);
  }
}

// "ends at byte X of a Y-byte file" when [offset, offset + length) does not lie within `size`
// bytes; empty when it does. An end past 2^64 is said as such (no wrap-around).
inline std::string past_end(std::uint64_t offset, std::uint64_t length, std::uint64_t size) {
  if (offset <= size && length <= size - offset) return {};
  const std::string end = length > UINT64_MAX - offset
                              ? std::string("beyond byte 2^64")
                              : "at byte " + std::to_string(offset + length);
  return "ends " + end + " of a " + std::to_string(size) + "-byte file";
}

template <typename T>
bool read_struct(const ReadAt& read_at, std::uint64_t offset, T& out) {
  static_assert(std::is_trivially_copyable_v<T>);
  return read_at(offset, sizeof(T), &out);
}

}  // namespace detail

// Why the file of `size` bytes that `read_at` reads cannot be loaded as a shared library by this
// build; empty when, as far as its headers tell, it can. Phrased to follow "it ": "is
// truncated: its program header 3 ends at byte 20480 of a 10240-byte file".
inline std::string elf_problem(std::uint64_t size, const ReadAt& read_at) {
  using namespace detail;
  if (size == 0) return "is empty";
  unsigned char ident[EI_NIDENT] = {};
  const std::size_t have = size < EI_NIDENT ? static_cast<std::size_t>(size) : EI_NIDENT;
  if (!read_at(0, have, ident)) return "cannot be read (its first bytes)";
  const std::size_t magic = have < SELFMAG ? have : SELFMAG;
  if (std::memcmp(ident, ELFMAG, magic) != 0) {
    return "is not an ELF file (a shared library starts with \\x7fELF)";
  }
  const auto truncated_header = [size] {
    return "is truncated: its ELF header needs " + std::to_string(sizeof(Ehdr)) +
           " bytes, the file has " + std::to_string(size);
  };
  // The identification bytes first: a 32-bit header is shorter than a 64-bit one, and is
  // better named by its class than as a truncated 64-bit one.
  if (size < EI_NIDENT) return truncated_header();
  if (ident[EI_CLASS] != kHostClass) {
    if (ident[EI_CLASS] == ELFCLASS32 || ident[EI_CLASS] == ELFCLASS64) {
      return std::string("is a ") + (ident[EI_CLASS] == ELFCLASS32 ? "32" : "64") +
             "-bit ELF file; this nlobs is " + (kHost64 ? "64" : "32") + "-bit";
    }
    return "has an invalid ELF class (" + std::to_string(ident[EI_CLASS]) + ")";
  }
  if (ident[EI_DATA] != kHostData) {
    if (ident[EI_DATA] == ELFDATA2LSB || ident[EI_DATA] == ELFDATA2MSB) {
      return std::string("is ") + (ident[EI_DATA] == ELFDATA2MSB ? "big" : "little") +
             "-endian; this machine is " + (kHostData == ELFDATA2MSB ? "big" : "little") +
             "-endian";
    }
    return "has an invalid ELF byte order (" + std::to_string(ident[EI_DATA]) + ")";
  }
  if (ident[EI_VERSION] != EV_CURRENT) {
    return "has ELF version " + std::to_string(ident[EI_VERSION]) + ", not " +
           std::to_string(EV_CURRENT);
  }
  if (size < sizeof(Ehdr)) return truncated_header();
  Ehdr header;
  if (!read_struct(read_at, 0, header)) return "cannot be read (its ELF header)";
  if (header.e_type != ET_DYN) return "is not a shared library: " + type_name(header.e_type);
  if (kHostMachine != EM_NONE && header.e_machine != kHostMachine) {
    return "is built for " + machine_name(header.e_machine) + "; this nlobs runs on " +
           machine_name(kHostMachine);
  }

  // Extended numbering (ELF gABI): more than 0xfeff sections, or 0xffff program headers, are
  // counted in section header 0, which must then be within the file.
  std::uint64_t sections = header.e_shnum;
  std::uint64_t segments = header.e_phnum;
  if ((sections == 0 && header.e_shoff != 0) || segments == PN_XNUM) {
    if (header.e_shoff == 0) return "has an extended program header count but no section headers";
    if (const std::string end = past_end(header.e_shoff, sizeof(Shdr), size); !end.empty()) {
      return "is truncated: its section header 0 " + end;
    }
    Shdr first;
    if (!read_struct(read_at, header.e_shoff, first)) return "cannot be read (section header 0)";
    if (sections == 0) sections = first.sh_size;
    if (segments == PN_XNUM) segments = first.sh_info;
  }

  if (segments > 0) {
    if (header.e_phentsize != sizeof(Phdr)) {
      return "has program headers of " + std::to_string(header.e_phentsize) + " bytes, not " +
             std::to_string(sizeof(Phdr)) + " (a damaged ELF header)";
    }
    // segments <= 0xffffffff and sizeof(Phdr) <= 56: the product does not overflow.
    if (const std::string end = past_end(header.e_phoff, segments * sizeof(Phdr), size);
        !end.empty()) {
      return "is truncated: its program header table " + end;
    }
    for (std::uint64_t i = 0; i < segments; ++i) {
      Phdr segment;
      if (!read_struct(read_at, header.e_phoff + i * sizeof(Phdr), segment)) {
        return "cannot be read (program header " + std::to_string(i) + ")";
      }
      if (const std::string end = past_end(segment.p_offset, segment.p_filesz, size);
          !end.empty()) {
        return "is truncated: its program header " + std::to_string(i) + " " + end;
      }
    }
  }

  if (sections > 0) {
    if (header.e_shentsize != sizeof(Shdr)) {
      return "has section headers of " + std::to_string(header.e_shentsize) + " bytes, not " +
             std::to_string(sizeof(Shdr)) + " (a damaged ELF header)";
    }
    // Checked against the size before multiplying: sections may be any 64-bit count here.
    if (sections > size / sizeof(Shdr)) {
      return "is truncated: its section header table (" + std::to_string(sections) +
             " sections) is larger than the " + std::to_string(size) + "-byte file";
    }
    if (const std::string end = past_end(header.e_shoff, sections * sizeof(Shdr), size);
        !end.empty()) {
      return "is truncated: its section header table " + end;
    }
    for (std::uint64_t i = 0; i < sections; ++i) {
      Shdr section;
      if (!read_struct(read_at, header.e_shoff + i * sizeof(Shdr), section)) {
        return "cannot be read (section header " + std::to_string(i) + ")";
      }
      if (section.sh_type == SHT_NOBITS || section.sh_type == SHT_NULL) continue;  // no bytes
      if (const std::string end = past_end(section.sh_offset, section.sh_size, size);
          !end.empty()) {
        return "is truncated: its section " + std::to_string(i) + " " + end;
      }
    }
  }
  return {};
}

// The same, for a file held in memory (the fuzz target, the tests).
inline std::string elf_problem(std::string_view file) {
  return elf_problem(file.size(), [file](std::uint64_t offset, std::size_t count, void* out) {
    if (offset > file.size() || count > file.size() - offset) return false;
    if (count > 0) std::memcpy(out, file.data() + offset, count);
    return true;
  });
}

}  // namespace nlobs::plugin_file
