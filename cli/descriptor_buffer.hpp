#pragma once
// A streambuf over a file descriptor that keeps the first failing write's errno, so that a
// failure says "No space left on device" rather than a stream's bare failbit. The CLI writes
// its output files (OutputFile) and standard output through it.
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstddef>
#include <streambuf>

namespace nlobs::cli {

class DescriptorBuffer : public std::streambuf {
 public:
  // line_buffered: write at every '\n' (a terminal, where output and messages interleave).
  void attach(int fd, bool line_buffered = false) {
    fd_ = fd;
    line_buffered_ = line_buffered;
    setp(buffer_.data(), buffer_.data() + buffer_.size());
  }
  int error() const { return error_; }  // 0 while every write succeeded
  bool written() const { return written_; }
  // Writes what is buffered; false (error() says why) when the descriptor refused it. After a
  // failure nothing more is written: the output is already incomplete.
  bool drain() {
    const char* p = pbase();
    std::size_t left = static_cast<std::size_t>(pptr() - pbase());
    while (left > 0 && error_ == 0) {
      const ssize_t n = ::write(fd_, p, left);
      if (n < 0) {
        if (errno == EINTR) continue;
        error_ = errno;
        break;
      }
      if (n == 0) {  // no progress on a nonzero count: the device is full
        error_ = ENOSPC;
        break;
      }
      written_ = true;
      p += n;
      left -= static_cast<std::size_t>(n);
    }
    setp(buffer_.data(), buffer_.data() + buffer_.size());
    return error_ == 0;
  }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
      if (line_buffered_ && traits_type::to_char_type(c) == '\n' && !drain()) {
        return traits_type::eof();
      }
    }
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    std::streamsize done = 0;
    while (done < n) {
      if (pptr() == epptr() && !drain()) return done;
      const std::streamsize room = epptr() - pptr();
      const std::streamsize chunk = room < n - done ? room : n - done;
      traits_type::copy(pptr(), s + done, static_cast<std::size_t>(chunk));
      pbump(static_cast<int>(chunk));
      done += chunk;
    }
    if (line_buffered_ && n > 0 && traits_type::find(s, static_cast<std::size_t>(n), '\n') &&
        !drain()) {
      return 0;
    }
    return n;
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  int fd_ = -1;
  int error_ = 0;
  bool written_ = false;
  bool line_buffered_ = false;
  std::array<char, 1 << 16> buffer_{};
};

}  // namespace nlobs::cli
