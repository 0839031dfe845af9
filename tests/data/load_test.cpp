#include "pneumid/data/load.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "test_files.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(LoadTest, FormatFromPath) {
  EXPECT_EQ(DataFormatFromPath("a/b.CSV"), DataFormat::kCsv);
  EXPECT_EQ(DataFormatFromPath("x.tsv"), DataFormat::kCsv);
  EXPECT_EQ(DataFormatFromPath("x.dat"), DataFormat::kCsv);
  EXPECT_EQ(DataFormatFromPath("x.txt"), DataFormat::kCsv);
  EXPECT_EQ(DataFormatFromPath("run.mat"), DataFormat::kMat);
  EXPECT_THAT(
      [] { DataFormatFromPath("dir.v2/run.xlsx"); },
      ThrowsMessage<DataError>(HasSubstr("dir.v2/run.xlsx: unknown data file extension '.xlsx'")));
  EXPECT_THROW(DataFormatFromPath("noext"), DataError);
  for (auto f : {DataFormat::kAuto, DataFormat::kCsv, DataFormat::kMat}) {
    EXPECT_EQ(DataFormatFromString(ToString(f)), f);
  }
  EXPECT_THROW(DataFormatFromString("xls"), InvalidArgument);
}

TEST(LoadTest, SaveAndLoadEveryFormat) {
  testing::TempDir dir;
  Eigen::VectorXd u(4), y(4);
  u << 0.61, 82, 82, 82;
  y << 0, 30.25, 55.5, 1.0 / 7.0;
  const Dataset d = Dataset::FromUniform(0.01, u, y);
  for (const std::string name : {"a.csv", "a.tsv", "a.txt", "a.dat", "a.mat"}) {
    const std::string path = dir.Path(name);
    SaveDataset(d, path);
    const Dataset r = LoadDataset(path);
    EXPECT_EQ(r.time(), d.time()) << name;
    EXPECT_EQ(r.u(), d.u()) << name;
    EXPECT_EQ(r.y(), d.y()) << name;
  }
  // An explicit format overrides the extension.
  SaveOptions s;
  s.format = DataFormat::kMat;
  SaveDataset(d, dir.Path("really_mat.bin"), s);
  LoadOptions o;
  o.format = DataFormat::kMat;
  EXPECT_EQ(LoadDataset(dir.Path("really_mat.bin"), o).size(), 4);
  EXPECT_THROW(LoadDataset(dir.Path("really_mat.bin")), DataError);
}

TEST(LoadTest, OptionsReachTheReaders) {
  testing::TempDir dir;
  const std::string csv = dir.Write("p.csv", "duty;F\n1;2\n3;4\n");
  LoadOptions o;
  o.input_columns = {"duty"};
  o.output_columns = {"1"};
  o.sample_time = 0.5;
  const Dataset d = LoadDataset(csv, o);
  EXPECT_DOUBLE_EQ(d.time()[1], 0.5);
  EXPECT_DOUBLE_EQ(d.y()[1], 4.0);
  o.sample_time = -1.0;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THROW(LoadDataset(csv, o), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
