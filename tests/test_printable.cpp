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
  EXPECT_EQ(nlobs::printable("a\nb\tc\rd\x1b[2Je\x07"), "a\\nb\\tc\\rd\\e[2Je\\x07");
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

TEST(Printable, BoundsTheLengthAndSaysWhatWasCut) {
  const std::string name(10000, 'a');
  const std::string shown = nlobs::printable(name, 60);
  EXPECT_EQ(shown, std::string(60, 'a') + "…(+9940 bytes)");
  EXPECT_EQ(nlobs::printable(std::string(60, 'a'), 60), std::string(60, 'a'));
  // A cut never splits a character.
  std::string wide;
  for (int i = 0; i < 100; ++i) wide += "θ";
  const std::string cut = nlobs::printable(wide, 5);
  EXPECT_EQ(cut.substr(0, 6), "θθθ");
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
    EXPECT_EQ(nlobs::current_exception_text(), "bad\\nline");
  }
}

}  // namespace
