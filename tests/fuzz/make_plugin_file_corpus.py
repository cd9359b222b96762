#!/usr/bin/env python3
"""Writes the seed corpus of fuzz_plugin_file (tests/fuzz/corpus/plugin_file): small ELF files,
valid and damaged, for the plugin loader's checks (registry/src/plugin_file.hpp). Little-endian
x86-64 like the machine the fuzzer runs on (on another machine they reach the machine check).
Run from the repository root: python3 tests/fuzz/make_plugin_file_corpus.py"""
import os
import struct

EHDR64, PHDR64, SHDR64 = 64, 56, 64
ET_DYN, ET_EXEC, EM_X86_64 = 3, 2, 62
PT_LOAD, PT_DYNAMIC = 1, 2
SHT_PROGBITS, SHT_NOBITS = 1, 8


def ehdr(phoff, phnum, shoff, shnum, etype=ET_DYN, cls=2, data=1, machine=EM_X86_64):
    ident = b"\x7fELF" + bytes([cls, data, 1, 0]) + bytes(8)
    return ident + struct.pack("<HHIQQQIHHHHHH", etype, machine, 1, 0, phoff, shoff, 0, EHDR64,
                               PHDR64, phnum, SHDR64, shnum, 0)


def phdr(ptype, offset, filesz, memsz=None):
    return struct.pack("<IIQQQQQQ", ptype, 5, offset, offset, offset, filesz,
                       filesz if memsz is None else memsz, 0x1000)


def shdr(stype, offset, size, info=0):
    return struct.pack("<IIQQQQIIQQ", 0, stype, 0, 0, offset, size, 0, info, 1, 0)


def minimal(segment_size=None):
    """Header, two program headers, 16 bytes of data, three section headers (null, data, bss).
    The loadable segment ends with the data: section headers are not loaded (as in a linker's
    output, where they end the file)."""
    data_offset = EHDR64 + 2 * PHDR64
    shoff = data_offset + 16
    return (ehdr(EHDR64, 2, shoff, 3) +
            phdr(PT_LOAD, 0, shoff if segment_size is None else segment_size) +
            phdr(PT_DYNAMIC, data_offset, 16) + bytes(range(16)) +
            shdr(0, 0, 0) + shdr(SHT_PROGBITS, data_offset, 16) + shdr(SHT_NOBITS, 0, 1 << 20))


def extended_numbering():
    """e_phnum = PN_XNUM and e_shnum = 0: the counts are in section header 0."""
    shoff = EHDR64 + PHDR64
    return (ehdr(EHDR64, 0xFFFF, shoff, 0) + phdr(PT_LOAD, 0, shoff + SHDR64) +
            shdr(0, 0, 1, info=1))


seeds = {
    "minimal.so": minimal(),
    "header_only.so": ehdr(0, 0, 0, 0),
    "truncated_header.so": minimal()[:40],
    "truncated_segment.so": minimal(segment_size=1 << 16),
    "truncated_sections.so": minimal()[:-1],
    "executable.so": ehdr(0, 0, 0, 0, etype=ET_EXEC),
    "elf32.so": b"\x7fELF" + bytes([1, 1, 1, 0]) + bytes(44),
    "big_endian.so": b"\x7fELF" + bytes([2, 2, 1, 0]) + bytes(56),
    "extended_numbering.so": extended_numbering(),
    "text.so": b"not a shared library\n",
}
here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "plugin_file")
os.makedirs(here, exist_ok=True)
for name, data in seeds.items():
    with open(os.path.join(here, name), "wb") as f:
        f.write(data)
