// What `nlobs run` reads from the user: the --data CSV reader line by line (a header only when it
// is one, a BOM, empty last cells, increasing times, out-of-range numbers, hostile bytes), input
// files that are directories or missing, and JSON numbers beyond a double.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "nlobs/registry/json_reader.hpp"
#include "nlobs/runs/input_file.hpp"
#include "nlobs/runs/measurements_file.hpp"
#include "nlobs/runs/scenario.hpp"

namespace nlobs::cli {
namespace {

namespace fs = std::filesystem;

Measurements parse(const std::string& text, Eigen::Index outputs = 1, Eigen::Index inputs = 0) {
  std::istringstream in(text);
  return parse_measurements_csv(in, "d.csv", outputs, inputs);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "<no error>";
}

std::string parse_error(const std::string& text, Eigen::Index outputs = 1,
                        Eigen::Index inputs = 0) {
  return error_of([&] { parse(text, outputs, inputs); });
}

fs::path scratch(const std::string& name) {
  const fs::path p =
      fs::temp_directory_path() / ("nlobs_test_inputs_" + std::to_string(::getpid())) / name;
  fs::create_directories(p.parent_path());
  return p;
}

TEST(DataFile, HeaderOnlyWhenNoCellIsANumber) {
  const Measurements with = parse("t,y1\n0,1.5\n0.1,2.5\n");
  ASSERT_EQ(with.steps(), 2);
  EXPECT_EQ(with.y(0, 0), 1.5);
  // No header: the first row is data, not skipped (it was when it failed to parse).
  const Measurements without = parse("0,1.5\n0.1,2.5\n");
  ASSERT_EQ(without.steps(), 2);
  EXPECT_EQ(without.t[0], 0.0);
  // A header-like line that mixes text and numbers is an error naming the line and the cell.
  const std::string mixed = parse_error("t,5\n0,1\n");
  EXPECT_NE(mixed.find("d.csv:1: cell 1 't' is not a number"), std::string::npos) << mixed;
  EXPECT_NE(mixed.find("a header line has no numbers"), std::string::npos) << mixed;
  // A malformed first row is not taken for a header: "0.1x,2" has a number in it.
  EXPECT_NE(parse_error("0.1x,2\n0.2,3\n").find("d.csv:1: cell 1 '0.1x' is not a number"),
            std::string::npos);
  // A header of the wrong width.
  EXPECT_NE(parse_error("t,y1,y2\n0,1\n").find("d.csv:1: a header of 3 columns; expected 2"),
            std::string::npos);
  // A second header further down is a malformed row.
  EXPECT_NE(parse_error("t,y1\n0,1\nt,y1\n").find("d.csv:3: cell 1 't' is not a number"),
            std::string::npos);
}

TEST(DataFile, ByteOrderMarkIsSkipped) {
  // Without the header and with a BOM, the first row used to be lost as a "header".
  const Measurements m = parse(
      "\xEF\xBB\xBF"
      "0,1.5\n0.1,2.5\n");
  ASSERT_EQ(m.steps(), 2);
  EXPECT_EQ(m.y(0, 0), 1.5);
  EXPECT_EQ(parse("\xEF\xBB\xBFt,y1\r\n0,1\r\n").steps(), 1);  // with a header, CRLF
}

TEST(DataFile, EmptyCellsAndNanAreMissingMeasurements) {
  const Measurements m = parse("0,1,\n0.1,,2\n0.2,nan,NaN\n0.3, 4 ,5\n", 2);
  ASSERT_EQ(m.steps(), 4);
  EXPECT_EQ(m.y(0, 0), 1.0);
  EXPECT_TRUE(std::isnan(m.y(1, 0)));  // the empty last cell ("got 1 column" before)
  EXPECT_TRUE(std::isnan(m.y(0, 1)));
  EXPECT_TRUE(std::isnan(m.y(0, 2)) && std::isnan(m.y(1, 2)));
  EXPECT_EQ(m.y(0, 3), 4.0);  // blanks around a number
  // Missing time or input is an error, not a missing value.
  EXPECT_NE(parse_error("0,1\n,2\n").find("d.csv:2: t is missing"), std::string::npos);
  EXPECT_NE(parse_error("0,1,\n", 1, 1).find("d.csv:1: u1 is missing"), std::string::npos);
}

TEST(DataFile, TimesMustIncrease) {
  const std::string repeated = parse_error("0,1\n0.1,2\n0.1,3\n");
  EXPECT_NE(repeated.find("d.csv:3: time 0.10000000000000001 does not come after the previous"),
            std::string::npos)
      << repeated;
  EXPECT_NE(parse_error("0,1\n0.2,2\n0.1,3\n").find("d.csv:3:"), std::string::npos);
  EXPECT_NE(parse_error("0,1\ninf,2\n").find("d.csv:2: t is infinite"), std::string::npos);
  // Blank lines are skipped but still counted: the message names the file's own line.
  EXPECT_NE(parse_error("0,1\n\n\n0,3\n").find("d.csv:4:"), std::string::npos);
}

TEST(DataFile, OutOfRangeAndInfiniteValuesAreNamed) {
  const std::string overflow = parse_error("0,1e400\n");
  EXPECT_NE(overflow.find("d.csv:1: y1 '1e400' is out of the range of a double"), std::string::npos)
      << overflow;
  EXPECT_NE(parse_error("0,-inf\n").find("y1 is infinite (a missing measurement is"),
            std::string::npos);
  EXPECT_NE(parse_error("0,1,inf\n", 1, 1).find("u1 is infinite"), std::string::npos);
  EXPECT_EQ(parse("0,1e-400\n").y(0, 0), 0.0);  // an underflow is the nearest double
  // A number is the whole cell: an embedded NUL does not end it; a long one is still a number.
  EXPECT_NE(parse_error(std::string("0,1\0abc\n", 8)).find("cell 2 '1\\x00abc' is not a number"),
            std::string::npos);
  const std::string long_number = "0." + std::string(100, '0') + "15";
  EXPECT_EQ(parse("0," + long_number + "\n").y(0, 0), 1.5e-101);
}

TEST(DataFile, HostileBytesGiveShortMessages) {
  const std::string huge((1 << 20) - 10, 'x');  // just within a line's limit
  const std::string e = parse_error("0," + huge + "\n");
  EXPECT_LT(e.size(), 200U);
  EXPECT_NE(e.find("cell 2 'xxxx"), std::string::npos) << e;
  const std::string control = parse_error(std::string("0,\x1b[31m\0x", 9) + "\n");
  EXPECT_NE(control.find("\\x1b[31m\\x00x"), std::string::npos) << control;
  EXPECT_NE(parse_error("0,1,2\n").find("expected 2 columns (t, 1 output), got 3"),
            std::string::npos);
  EXPECT_NE(parse_error("").find("d.csv: no data rows"), std::string::npos);
  EXPECT_NE(parse_error("t,y1\n\n").find("no data rows"), std::string::npos);
}

// A line of any length used to be read whole: /dev/zero grew to 1 GB, then "read error" named
// no line.
TEST(DataFile, ALineBeyondTheLimitIsNamedWithItsNumber) {
  const std::string beyond = parse_error("t,y1\n0,1\n" + std::string(kMaxDataLineBytes + 1, '0'));
  EXPECT_NE(beyond.find("d.csv:3: the line is longer than 1048576 bytes"), std::string::npos)
      << beyond;
  // At the limit a line is read: what is wrong with it is its number, not its length.
  const std::string at = parse_error("0," + std::string(kMaxDataLineBytes - 2, '1') + "\n");
  EXPECT_EQ(at.find("longer than"), std::string::npos) << at.substr(0, 200);
  EXPECT_NE(at.find("d.csv:1:"), std::string::npos) << at.substr(0, 200);
  const std::string zeros = error_of([] { read_measurements_csv("/dev/zero", 1, 0); });
  EXPECT_NE(zeros.find("/dev/zero:1: the line is longer than"), std::string::npos) << zeros;
  // A last line without a line break is read as a line.
  EXPECT_EQ(parse("0,1\n1,2").steps(), 2);
}

TEST(DataFile, InputsAndSeveralOutputs) {
  const Measurements m = parse("t,y1,y2,u1\n0,1,2,3\n1,4,,6\n", 2, 1);
  ASSERT_EQ(m.steps(), 2);
  EXPECT_EQ(m.u(0, 1), 6.0);
  EXPECT_EQ(m.y(1, 0), 2.0);
  EXPECT_TRUE(std::isnan(m.y(1, 1)));
}

TEST(InputFile, DirectoriesAndMissingFilesAreNamed) {
  const fs::path dir = scratch("a-directory");
  fs::create_directories(dir);
  EXPECT_NE(error_of([&] {
              read_measurements_csv(dir.string(), 1, 0);
            }).find("data file '" + dir.string() + "' is a directory"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              read_measurements_csv((dir / "none.csv").string(), 1, 0);
            }).find("does not exist"),
            std::string::npos);
  const std::string scenario = error_of([&] { load_scenario(dir.string()); });
  EXPECT_NE(scenario.find("scenario file '" + dir.string() + "' is a directory"), std::string::npos)
      << scenario;
  EXPECT_NE(error_of([&] {
              load_scenario((dir / "none.json").string());
            }).find("is neither a built-in scenario"),
            std::string::npos);
}

TEST(JsonInput, NumberBeyondADoubleNamesTheFileAndKey) {
  std::istringstream in(R"({"name": "x", "model": {"name": "chua", "step": 1e400}})");
  const std::string e = error_of([&] { parse_json(in, "s.json"); });
  EXPECT_NE(e.find("s.json: near key 'step': a number is out of the range of a double"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace nlobs::cli
