#include "pneumid/data/csv.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "test_files.hpp"

namespace pneumid {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

class CsvTest : public ::testing::Test {
 protected:
  std::string Write(const std::string& content, const std::string& name = "data.csv") {
    return dir_.Write(name, content);
  }
  /// Asserts that reading `content` throws DataError naming file:line and the column.
  void ExpectError(const std::string& content, int line, const std::string& column,
                   const std::string& what, const CsvReadOptions& options = {}) {
    const std::string path = Write(content);
    const std::string where = path + ":" + std::to_string(line) + ":";
    EXPECT_THAT(
        [&] { ReadCsv(path, options); },
        ThrowsMessage<DataError>(AllOf(HasSubstr(where), HasSubstr(column), HasSubstr(what))))
        << content;
  }
  testing::TempDir dir_;
};

TEST_F(CsvTest, ReadsCommaSeparatedWithHeaderAndComments) {
  const std::string path = Write(
      "# step test of the IPA\n"
      "# second comment\n"
      "t,u,y\n"
      "0.00,0.61,0\n"
      "0.01,82,1.5   # valve opened\n"
      "\n"
      "0.02,82,3.25\n");
  const Dataset d = ReadCsv(path);
  ASSERT_EQ(d.size(), 3);
  EXPECT_EQ(d.num_inputs(), 1);
  EXPECT_EQ(d.num_outputs(), 1);
  EXPECT_DOUBLE_EQ(d.time()[2], 0.02);
  EXPECT_DOUBLE_EQ(d.u()[0], 0.61);
  EXPECT_DOUBLE_EQ(d.u()[1], 82.0);
  EXPECT_DOUBLE_EQ(d.y()[2], 3.25);
  EXPECT_EQ(d.source(), path);
  EXPECT_EQ(d.input_channels()[0].name, "u");
  // Lines: header on 3, samples on 4, 5 and (after a blank line) 7.
  EXPECT_EQ(d.SourceLine(0), 4);
  EXPECT_EQ(d.SourceLine(1), 5);
  EXPECT_EQ(d.SourceLine(2), 7);
  EXPECT_EQ(d.Where(2), path + ":7");
}

TEST_F(CsvTest, DetectsSemicolonTabAndBlankDelimiters) {
  for (const std::string& text :
       {std::string("t;u;y\n0;1;2\n1;3;4\n"), std::string("t\tu\ty\n0\t1\t2\n1\t3\t4\n"),
        std::string("  t   u  y\n 0  1   2\n1 3 4\n"), std::string("t,u,y\r\n0,1,2\r\n1,3,4\r\n"),
        std::string("\xEF\xBB\xBFt,u,y\n0,1,2\n1,3,4")}) {
    const Dataset d = ReadCsv(Write(text));
    ASSERT_EQ(d.size(), 2) << text;
    EXPECT_DOUBLE_EQ(d.u()[1], 3.0) << text;
    EXPECT_DOUBLE_EQ(d.y()[1], 4.0) << text;
  }
}

TEST_F(CsvTest, ExplicitDelimiter) {
  CsvReadOptions o;
  o.delimiter = ';';
  // With ';' forced, the comma is part of the cell and is not a number.
  ExpectError("t;u;y\n0;1,5;2\n", 2, "'u'", "not a number: '1,5' (numbers need '.'", o);
  const Dataset d = ReadCsv(Write("t;u;y\n0;1;2\n"), o);
  EXPECT_DOUBLE_EQ(d.y()[0], 2.0);
}

TEST_F(CsvTest, SelectsColumnsByNameAndIndexAndParsesUnits) {
  const std::string path = Write(
      "time [s],duty (%),\"F [N]\",P1\n"
      "0,1,10,100\n"
      "0.5,2,20,200\n");
  CsvReadOptions o;
  o.time_column = "time";
  o.input_columns = {"duty"};
  o.output_columns = {"F", "3"};
  const Dataset d = ReadCsv(path, o);
  ASSERT_EQ(d.num_outputs(), 2);
  EXPECT_DOUBLE_EQ(d.time()[1], 0.5);
  EXPECT_DOUBLE_EQ(d.u()[1], 2.0);
  EXPECT_DOUBLE_EQ(d.y(0)[1], 20.0);
  EXPECT_DOUBLE_EQ(d.y(1)[1], 200.0);
  EXPECT_EQ(d.input_channels()[0].name, "duty");
  EXPECT_EQ(d.input_channels()[0].unit, "%");
  EXPECT_EQ(d.output_channels()[0].name, "F");
  EXPECT_EQ(d.output_channels()[0].unit, "N");
  EXPECT_EQ(d.output_channels()[1].name, "P1");
  EXPECT_EQ(d.time_channel().name, "time");

  o.time_column = "0";  // by index
  o.input_columns = {"1"};
  o.output_columns = {"F [N]"};  // by full label
  const Dataset e = ReadCsv(path, o);
  EXPECT_DOUBLE_EQ(e.u()[0], 1.0);
  EXPECT_DOUBLE_EQ(e.y()[0], 10.0);
}

TEST_F(CsvTest, SampleTimeWithoutTimeColumn) {
  CsvReadOptions o;
  o.sample_time = 0.01;
  o.start_time = 2.0;
  const Dataset d = ReadCsv(Write("u,y\n1,2\n3,4\n5,6\n"), o);
  ASSERT_EQ(d.size(), 3);
  EXPECT_DOUBLE_EQ(d.time()[0], 2.0);
  EXPECT_DOUBLE_EQ(d.time()[2], 2.02);
  EXPECT_NEAR(d.SampleTime(), 0.01, 1e-15);
}

TEST_F(CsvTest, BlocksHoldTheSamplesOfReadCsv) {
  const std::string path = Write("# c\nt,u,F [N]\n0,1,10\n0.5,2,20\n\n1,3,30\n1.5,4,40\n2,5,50\n");
  CsvReadOptions o;
  o.output_columns = {"F"};
  const Dataset d = ReadCsv(path, o);
  for (const std::size_t block_rows : {1, 2, 5, 100}) {
    Eigen::VectorXd t(0), u(0), y(0);
    std::vector<Eigen::Index> firsts;
    double fraction = 0.0;
    const Eigen::Index n = ReadCsvBlocks(path, o, block_rows, [&](const CsvBlock& b) {
      EXPECT_LE(b.time.size(), static_cast<Eigen::Index>(block_rows));
      EXPECT_EQ(b.inputs.rows(), b.time.size());
      EXPECT_EQ(b.outputs.cols(), 1);
      EXPECT_GT(b.fraction_read, fraction);
      fraction = b.fraction_read;
      firsts.push_back(b.first_sample);
      const Eigen::Index k = t.size();
      t.conservativeResize(k + b.time.size());
      u.conservativeResize(k + b.time.size());
      y.conservativeResize(k + b.time.size());
      t.tail(b.time.size()) = b.time;
      u.tail(b.time.size()) = b.inputs.col(0);
      y.tail(b.time.size()) = b.outputs.col(0);
    });
    EXPECT_EQ(n, 5);
    EXPECT_EQ(t, d.time());
    EXPECT_EQ(u, d.u());
    EXPECT_EQ(y, d.y());
    EXPECT_EQ(firsts.size(), (5 + block_rows - 1) / block_rows) << block_rows;
    EXPECT_EQ(firsts.back(), static_cast<Eigen::Index>((firsts.size() - 1) * block_rows));
    EXPECT_DOUBLE_EQ(fraction, 1.0);
  }
}

TEST_F(CsvTest, BlocksWithGeneratedTimeAndErrors) {
  CsvReadOptions o;
  o.sample_time = 0.01;
  o.start_time = 2.0;
  const std::string path = Write("u,y\n1,2\n3,4\n5,6\n");
  std::vector<double> times;
  ReadCsvBlocks(path, o, 2, [&](const CsvBlock& b) {
    for (Eigen::Index i = 0; i < b.time.size(); ++i) times.push_back(b.time[i]);
  });
  ASSERT_EQ(times.size(), 3u);
  EXPECT_DOUBLE_EQ(times[2], 2.0 + 2 * 0.01);
  // A bad row is reported with file and line after the blocks before it.
  const std::string bad = Write("t,u,y\n0,1,2\n1,1,2\n2,x,2\n", "bad.csv");
  int blocks = 0;
  EXPECT_THAT([&] { ReadCsvBlocks(bad, {}, 1, [&](const CsvBlock&) { ++blocks; }); },
              ThrowsMessage<DataError>(AllOf(HasSubstr(bad + ":4:"), HasSubstr("'u'"))));
  EXPECT_EQ(blocks, 2);
  EXPECT_THAT([&] { ReadCsvBlocks(path, o, 0, [](const CsvBlock&) {}); },
              ThrowsMessage<InvalidArgument>(HasSubstr("block_rows must be > 0")));
}

TEST_F(CsvTest, OutputOnlyData) {
  CsvReadOptions o;
  o.input_columns = {};
  const Dataset d = ReadCsv(Write("t,y\n0,2\n1,4\n"), o);
  EXPECT_EQ(d.num_inputs(), 0);
  EXPECT_EQ(d.num_outputs(), 1);
}

TEST_F(CsvTest, NumberFormats) {
  const Dataset d = ReadCsv(Write("t,u,y\n-1.5e-3,+2,\" 3.25 \"\n1e2,-0,.5\n"));
  EXPECT_DOUBLE_EQ(d.time()[0], -1.5e-3);
  EXPECT_DOUBLE_EQ(d.u()[0], 2.0);
  EXPECT_DOUBLE_EQ(d.y()[0], 3.25);
  EXPECT_DOUBLE_EQ(d.time()[1], 100.0);
  EXPECT_DOUBLE_EQ(d.y()[1], 0.5);
}

TEST_F(CsvTest, UnselectedTextColumnsAreIgnored) {
  const Dataset d = ReadCsv(Write("t,u,y,note\n0,1,2,start\n1,1,2,\n"));
  EXPECT_EQ(d.size(), 2);
}

// ---- every bad-input case names file, line and column ----------------------

TEST_F(CsvTest, NaNCell) { ExpectError("t,u,y\n0,1,2\n1,nan,3\n", 3, "column 'u'", "NaN"); }

TEST_F(CsvTest, InfCell) { ExpectError("t,u,y\n0,1,2\n1,1,-inf\n", 3, "column 'y'", "infinite"); }

TEST_F(CsvTest, NonNumericCell) {
  ExpectError("t,u,y\n0,1,2\n1,1,2\n2,abc,3\n", 4, "column 'u'", "not a number: 'abc'");
  ExpectError("t,u,y\n0,1,2x\n", 2, "column 'y'", "not a number: '2x'");
}

TEST_F(CsvTest, OutOfRangeNumber) {
  ExpectError("t,u,y\n0,1,1e999\n", 2, "column 'y'", "out of range");
}

TEST_F(CsvTest, MissingCell) {
  ExpectError("t,u,y\n0,1,2\n1,,3\n", 3, "column 'u'", "missing value");
}

TEST_F(CsvTest, RaggedRow) {
  ExpectError("t,u,y\n0,1,2\n1,2\n", 3, "header (line 1) has 3 columns", "row has 2 cells");
  ExpectError("t,u,y\n0,1,2,4\n", 2, "has 3 columns", "row has 4 cells");
}

TEST_F(CsvTest, TimeNotStrictlyIncreasing) {
  ExpectError("t,u,y\n0,1,2\n0.01,1,2\n0.01,1,2\n", 4, "column 't'",
              "time is not strictly increasing: t = 0.01 after t = 0.01 on line 3");
  ExpectError("t,u,y\n0,1,2\n-1,1,2\n", 3, "column 't'", "not strictly increasing");
}

TEST_F(CsvTest, EmptyFile) {
  ExpectError("", 1, "", "empty file");
  ExpectError("# only a comment\n\n", 2, "", "empty file");
}

// Lines ended by a carriage return alone (classic Mac OS) read as one line:
// the error says so (it was an unknown column among 603 header cells);
// CR LF line ends read as before.
TEST_F(CsvTest, CarriageReturnLineEndsAreNamed) {
  ExpectError("t,u,y\r0,1,2\r0.1,1,3\r", 1, "", "carriage return alone");
  const Dataset d = ReadCsv(Write("t,u,y\r\n0,1,2\r\n0.1,1,3\r\n"));
  EXPECT_EQ(d.size(), 2);
}

TEST_F(CsvTest, HeaderOnly) { ExpectError("# c\nt,u,y\n# nothing\n", 2, "", "header row only"); }

TEST_F(CsvTest, UnknownColumnListsAvailable) {
  CsvReadOptions o;
  o.output_columns = {"F"};
  ExpectError("t,u,y\n0,1,2\n", 1, "unknown output column 'F'", "available columns: 't', 'u', 'y'",
              o);
  o.output_columns = {"7"};
  ExpectError("t,u,y\n0,1,2\n", 1, "output column index 7 out of range", "3 columns", o);
  ExpectError("time,u,y\n0,1,2\n", 1, "unknown time column 't'", "'time'");
}

TEST_F(CsvTest, MissingFile) {
  const std::string path = dir_.Path("missing.csv");
  EXPECT_THAT([&] { ReadCsv(path); },
              ThrowsMessage<DataError>(AllOf(HasSubstr(path), HasSubstr("cannot open"))));
}

TEST_F(CsvTest, NonUniformSamplingNamesLineAndSuggestsResampling) {
  const std::string path = Write("t,u,y\n0,1,2\n0.01,1,2\n0.02,1,2\n0.05,1,2\n0.06,1,2\n");
  const Dataset d = ReadCsv(path);
  EXPECT_FALSE(d.IsUniform());
  EXPECT_THAT([&] { d.RequireUniform(); },
              ThrowsMessage<DataError>(AllOf(HasSubstr(path + ":5:"), HasSubstr("column 't'"),
                                             HasSubstr("not uniform"), HasSubstr("--resample"))));
}

TEST_F(CsvTest, TooFewSamplesForAMethod) {
  const std::string path = Write("t,u,y\n0,1,2\n0.01,1,2\n");
  const Dataset d = ReadCsv(path);
  EXPECT_THAT(
      [&] { d.RequireSamples(10, "ARX(3,3,1)"); },
      ThrowsMessage<DataError>(AllOf(HasSubstr(path), HasSubstr("ARX(3,3,1)"),
                                     HasSubstr("at least 10 samples"), HasSubstr("has 2"))));
  EXPECT_NO_THROW(d.RequireSamples(2, "x"));
}

TEST_F(CsvTest, InvalidOptions) {
  CsvReadOptions o;
  std::string error;
  o.delimiter = 'x';
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("delimiter"));
  EXPECT_THROW(ReadCsv(Write("t,u,y\n"), o), InvalidArgument);
  o = {};
  o.sample_time = -1;
  EXPECT_FALSE(o.IsValid(&error));
  o = {};
  o.input_columns = {};
  o.output_columns = {};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_TRUE(CsvReadOptions{}.IsValid(&error));
}

// ---- writing ----------------------------------------------------------------

TEST_F(CsvTest, RoundTripIsExact) {
  Eigen::VectorXd t(4), u(4), y(4);
  t << 0.0, 0.1, 0.2, 0.30000000000000004;
  u << 1.0 / 3.0, -2.5e-300, 7.0, 1e20;
  y << std::acos(-1.0), 0.0, -1.0, 123456789.123456789;
  Dataset d(t, u, y, {{"duty", "%"}}, {{"F", "N"}});
  const std::string path = dir_.Path("round.csv");
  CsvWriteOptions w;
  w.comments = {"written by the round-trip test"};
  WriteCsv(d, path, {{{"yhat", "N"}, y * 2.0}}, w);
  CsvReadOptions o;
  o.input_columns = {"duty"};
  o.output_columns = {"F", "yhat"};
  const Dataset r = ReadCsv(path, o);
  EXPECT_EQ(r.time(), d.time());
  EXPECT_EQ(r.u(), d.u());
  EXPECT_EQ(r.y(0), d.y());
  EXPECT_EQ(r.y(1), (y * 2.0).eval());
  EXPECT_EQ(r.input_channels()[0].unit, "%");
  EXPECT_EQ(r.output_channels()[0].unit, "N");
  EXPECT_EQ(r.SourceLine(0), 3);  // comment, header, then data
}

TEST_F(CsvTest, WriteTabSeparated) {
  Dataset d = Dataset::FromUniform(0.5, Eigen::VectorXd::Ones(3), Eigen::VectorXd::Zero(3));
  const std::string path = dir_.Path("out.tsv");
  CsvWriteOptions w;
  w.delimiter = '\t';
  WriteCsv(d, path, {}, w);
  std::ifstream in(path);
  std::string header, row;
  std::getline(in, header);
  std::getline(in, row);
  EXPECT_EQ(header, "t [s]\tu\ty");
  EXPECT_EQ(row, "0\t1\t0");
  EXPECT_EQ(ReadCsv(path).size(), 3);
}

TEST_F(CsvTest, WriteErrors) {
  Dataset d = Dataset::FromUniform(0.5, Eigen::VectorXd::Ones(3), Eigen::VectorXd::Zero(3));
  EXPECT_THROW(WriteCsv(d, dir_.Path("a.csv"), {{{"x", ""}, Eigen::VectorXd::Zero(2)}}),
               InvalidArgument);
  EXPECT_THAT([&] { WriteCsv(d, dir_.Path("no/such/dir.csv")); },
              ThrowsMessage<DataError>(HasSubstr("cannot write")));
}

}  // namespace
}  // namespace pneumid
