// printable(): user text echoed in messages carries no control sequence and is bounded.
#include <gtest/gtest.h>

#include <string>

#include "nlobs/common/printable.hpp"

namespace {

TEST(Printable, KeepsPlainTextAndUtf8) {
  EXPECT_EQ(nlobs::printable("newton:m=3"), "newton:m=3");
  EXPECT_EQ(nlobs::printable("Rössler θ ∂F 𝔽"), "Rössler θ ∂F 𝔽");
}

TEST(Printable, EscapesControlCharacters) {
  EXPECT_EQ(nlobs::printable("a\nb\tc\rd\x1b[2Je\x07"), "a\\x0ab\\x09c\\x0dd\\x1b[2Je\\x07");
  EXPECT_EQ(nlobs::printable(std::string("nul\0x", 5)), "nul\\x00x");
  EXPECT_EQ(nlobs::printable("del\x7f"), "del\\x7f");
  // C1 controls in UTF-8 (U+009B is a CSI on some terminals) and a raw C1 byte.
  EXPECT_EQ(nlobs::printable("csi\xc2\x9b"
                             "2J"),
            "csi\\xc2\\x9b2J");
  EXPECT_EQ(nlobs::printable("raw\x9b"), "raw\\x9b");
}

TEST(Printable, EscapesInvalidUtf8) {
  EXPECT_EQ(nlobs::printable("\xc0\xaf"), "\\xc0\\xaf");                    // overlong '/'
  EXPECT_EQ(nlobs::printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");           // a surrogate
  EXPECT_EQ(nlobs::printable("\xf4\x90\x80\x80"), "\\xf4\\x90\\x80\\x80");  // > U+10FFFF
  EXPECT_EQ(nlobs::printable("cut \xe2\x88"), "cut \\xe2\\x88");            // truncated sequence
}

TEST(Printable, BoundsTheLengthAndSaysWhereItWasCut) {
  const std::string name(10000, 'a');
  EXPECT_EQ(nlobs::printable(name, 60), std::string(60, 'a') + "...");
  EXPECT_EQ(nlobs::printable(std::string(60, 'a'), 60), std::string(60, 'a'));
  // A cut never splits a character: é (2 bytes) at bytes 4..5 does not fit 5.
  EXPECT_EQ(nlobs::printable("abcdé", 5), "abcd...");
  EXPECT_EQ(nlobs::printable("abcdé", 6), "abcdé");
  // Escapes count the bytes of the text, so the output stays within 4 · limit + 3.
  EXPECT_EQ(nlobs::printable(std::string(100, '\n'), 2), "\\x0a\\x0a...");
}

TEST(Printable, CurrentExceptionText) {
  try {
    throw 42;
  } catch (...) {
    EXPECT_EQ(nlobs::current_exception_text(), "a non-standard exception");
  }
  try {
    throw std::runtime_error("bad\nline");
  } catch (...) {
    EXPECT_EQ(nlobs::current_exception_text(), "bad\\x0aline");
  }
}

}  // namespace
