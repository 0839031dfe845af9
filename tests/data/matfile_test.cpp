#include "pneumid/data/matfile.hpp"

#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <matio.h>

#include "pneumid/common/check.hpp"
#include "test_files.hpp"

namespace pneumid {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

/// Writes variables with matio directly (the independent writer for the reader tests).
class MatBuilder {
 public:
  explicit MatBuilder(const std::string& path, mat_ft version = MAT_FT_MAT5)
      : mat_(Mat_CreateVer(path.c_str(), nullptr, version)) {}
  ~MatBuilder() {
    if (mat_ != nullptr) Mat_Close(mat_);
  }
  bool ok() const { return mat_ != nullptr; }
  void Double(const std::string& name, std::size_t rows, std::size_t cols,
              std::vector<double> column_major) {
    Write(name, MAT_C_DOUBLE, MAT_T_DOUBLE, rows, cols, column_major.data());
  }
  void Int16(const std::string& name, std::vector<std::int16_t> v) {
    Write(name, MAT_C_INT16, MAT_T_INT16, v.size(), 1, v.data());
  }
  void Char(const std::string& name, std::string s) {
    std::size_t dims[2] = {1, s.size()};
    matvar_t* v = Mat_VarCreate(name.c_str(), MAT_C_CHAR, MAT_T_UTF8, 2, dims, s.data(), 0);
    Mat_VarWrite(mat_, v, MAT_COMPRESSION_NONE);
    Mat_VarFree(v);
  }
  void Complex(const std::string& name, std::vector<double> re, std::vector<double> im) {
    mat_complex_split_t z{re.data(), im.data()};
    std::size_t dims[2] = {re.size(), 1};
    matvar_t* v =
        Mat_VarCreate(name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, &z, MAT_F_COMPLEX);
    Mat_VarWrite(mat_, v, MAT_COMPRESSION_NONE);
    Mat_VarFree(v);
  }

 private:
  void Write(const std::string& name, matio_classes c, matio_types t, std::size_t rows,
             std::size_t cols, void* data) {
    std::size_t dims[2] = {rows, cols};
    matvar_t* v = Mat_VarCreate(name.c_str(), c, t, 2, dims, data, 0);
    Mat_VarWrite(mat_, v, MAT_COMPRESSION_NONE);
    Mat_VarFree(v);
  }
  mat_t* mat_;
};

class MatFileTest : public ::testing::Test {
 protected:
  static Dataset Sample() {
    Eigen::VectorXd t(5), u(5);
    Eigen::MatrixXd y(5, 2);
    t << 0, 0.01, 0.02, 0.03, 0.04;
    u << 0.61, 82, 82, 82, 82;
    y << 0, 10, 1.5, 11, 3.25, 12, 5.5, 13, 7.125, 1.0 / 3.0;
    return Dataset(t, u, y);
  }
  void ExpectError(const std::string& path, const MatReadOptions& o,
                   const std::vector<std::string>& parts) {
    try {
      ReadMat(path, o);
      ADD_FAILURE() << "no DataError for " << path;
    } catch (const DataError& e) {
      EXPECT_THAT(e.what(), HasSubstr(path));
      for (const auto& p : parts) EXPECT_THAT(e.what(), HasSubstr(p));
    }
  }
  testing::TempDir dir_;
};

TEST_F(MatFileTest, RoundTripV5) {
  const Dataset d = Sample();
  const std::string path = dir_.Path("d.mat");
  WriteMat(d, path);
  MatReadOptions o;  // u is N x 1, y is N x 2 -> two outputs
  const Dataset r = ReadMat(path, o);
  EXPECT_EQ(r.time(), d.time());
  EXPECT_EQ(r.inputs(), d.inputs());
  EXPECT_EQ(r.outputs(), d.outputs());
  EXPECT_EQ(r.output_channels()[1].name, "y:1");
  EXPECT_EQ(r.source(), path);
  o.output_variables = {"y:1"};
  EXPECT_EQ(ReadMat(path, o).y(), d.y(1));
}

TEST_F(MatFileTest, RoundTripCompressedAndV73) {
  const Dataset d = Sample();
  MatWriteOptions w;
  w.compress = true;
  WriteMat(d, dir_.Path("z.mat"), w);
  EXPECT_EQ(ReadMat(dir_.Path("z.mat")).outputs(), d.outputs());
  w.version = MatVersion::kV73;
  if (MatHasV73()) {
    WriteMat(d, dir_.Path("h.mat"), w);
    const Dataset r = ReadMat(dir_.Path("h.mat"));
    EXPECT_EQ(r.time(), d.time());
    EXPECT_EQ(r.outputs(), d.outputs());
  } else {
    EXPECT_THAT([&] { WriteMat(d, dir_.Path("h.mat"), w); },
                ThrowsMessage<DataError>(HasSubstr("HDF5")));
  }
}

TEST_F(MatFileTest, SingleMatrixVariableByColumnIndex) {
  const std::string path = dir_.Path("m.mat");
  {
    MatBuilder b(path);
    // data = [t u y], 3 x 3, column-major.
    b.Double("data", 3, 3, {0, 0.5, 1, 1, 2, 2, 0, 0.25, 0.75});
  }
  MatReadOptions o;
  o.time_variable = "0";
  o.input_variables = {"1"};
  o.output_variables = {"data:2"};
  const Dataset d = ReadMat(path, o);
  ASSERT_EQ(d.size(), 3);
  EXPECT_DOUBLE_EQ(d.time()[1], 0.5);
  EXPECT_DOUBLE_EQ(d.u()[2], 2.0);
  EXPECT_DOUBLE_EQ(d.y()[2], 0.75);
  o.output_variables = {"5"};
  ExpectError(path, o, {"'data'", "output column 5 out of range", "3x3"});
}

TEST_F(MatFileTest, RowVectorsIntegerClassesAndSampleTime) {
  const std::string path = dir_.Path("r.mat");
  {
    MatBuilder b(path);
    b.Double("u", 1, 4, {1, 2, 3, 4});  // row vector
    b.Int16("y", {-3, 0, 7, 100});
  }
  MatReadOptions o;
  o.sample_time = 0.01;
  const Dataset d = ReadMat(path, o);
  ASSERT_EQ(d.size(), 4);
  EXPECT_DOUBLE_EQ(d.time()[3], 0.03);
  EXPECT_DOUBLE_EQ(d.u()[3], 4.0);
  EXPECT_DOUBLE_EQ(d.y()[0], -3.0);
  // Without sample time the missing time variable is an error listing variables.
  ExpectError(path, {}, {"unknown time variable 't'", "'u' (1x4 double)", "'y' (4x1 integer)"});
}

TEST_F(MatFileTest, Errors) {
  const std::string path = dir_.Path("bad.mat");
  {
    MatBuilder b(path);
    b.Double("t", 3, 1, {0, 1, 1});
    b.Double("t2", 3, 1, {0, 1, 2});
    b.Double("u", 3, 1, {0, 1, 2});
    b.Double("y", 2, 1, {0, 1});
    b.Double("ynan", 3, 1, {0, std::numeric_limits<double>::quiet_NaN(), 1});
    b.Double("y3", 3, 1, {0, 1, 2});
    b.Complex("z", {1, 2, 3}, {0, 1, 0});
    b.Char("name", "abc");
  }
  MatReadOptions o;
  o.time_variable = "t2";
  ExpectError(path, o, {"variable 'y' has 2 samples", "length mismatch"});
  o.output_variables = {"ynan"};
  ExpectError(path, o, {"variable 'ynan'", "sample 1", "NaN"});
  o.output_variables = {"z"};
  ExpectError(path, o, {"variable 'z'", "complex", "real numeric"});
  o.output_variables = {"name"};
  ExpectError(path, o, {"variable 'name'", "char"});
  o.output_variables = {"nope"};
  ExpectError(path, o, {"unknown output variable 'nope'", "available variables", "'t2'"});
  o.output_variables = {"1"};
  ExpectError(path, o, {"exactly one numeric matrix variable"});
  o.time_variable = "t";
  o.output_variables = {"y3"};
  ExpectError(path, o, {"variable 't' sample 2", "not strictly increasing"});
}

TEST_F(MatFileTest, NotAMatFile) {
  const std::string text = dir_.Write("text.mat", "t,u,y\n0,1,2\n");
  EXPECT_THAT([&] { ReadMat(text); },
              ThrowsMessage<DataError>(AllOf(HasSubstr(text), HasSubstr("cannot open as a MAT"))));
  const std::string empty = dir_.Write("empty.mat", "");
  EXPECT_THAT([&] { ReadMat(empty); }, ThrowsMessage<DataError>(HasSubstr("empty file")));
  EXPECT_THAT([&] { ReadMat(dir_.Path("missing.mat")); },
              ThrowsMessage<DataError>(HasSubstr("no such file")));
}

TEST_F(MatFileTest, OptionsAndVersions) {
  EXPECT_EQ(MatVersionFromString("v7.3"), MatVersion::kV73);
  EXPECT_EQ(MatVersionFromString(ToString(MatVersion::kV5)), MatVersion::kV5);
  EXPECT_THROW(MatVersionFromString("v6"), InvalidArgument);
  MatWriteOptions w;
  w.input_variable = "1u";
  std::string error;
  EXPECT_FALSE(w.IsValid(&error));
  EXPECT_THROW(WriteMat(Sample(), dir_.Path("x.mat"), w), InvalidArgument);
  MatReadOptions r;
  r.time_variable = "";
  EXPECT_FALSE(r.IsValid(&error));
  EXPECT_THROW(ReadMat(dir_.Path("x.mat"), r), InvalidArgument);
}

TEST_F(MatFileTest, ReadsFileWrittenByScipy) {
  // tests/data/scipy_v5.mat from gen_matfile.py (scipy.io.savemat, compressed v5).
  const std::string path = std::string(PNEUMID_SOURCE_DIR) + "/tests/data/scipy_v5.mat";
  const Dataset d = ReadMat(path);
  ASSERT_EQ(d.size(), 5);
  EXPECT_NEAR(d.time()[4], 0.04, 1e-15);
  EXPECT_DOUBLE_EQ(d.u()[0], 0.61);
  EXPECT_DOUBLE_EQ(d.y()[2], 35.0);
  MatReadOptions o;
  o.time_variable = "data:0";
  o.input_variables = {"data:1"};
  o.output_variables = {"data:2"};
  const Dataset m = ReadMat(path, o);
  EXPECT_NEAR(m.time()[1], 0.01, 1e-8);  // single precision
  EXPECT_NEAR(m.u()[0], 0.61, 1e-6);
  EXPECT_DOUBLE_EQ(m.y()[4], 80.0);
  o.output_variables = {"name"};
  ExpectError(path, o, {"variable 'name'", "char"});
}

TEST_F(MatFileTest, ReadsScipyFileWithStructCellAndSmallElements) {
  // tests/data/scipy_struct_cell.mat from gen_matfile.py: a struct, a cell,
  // small data elements at the end of their arrays (int8 [1 2 3], single
  // 2.5) and an empty array beside the signals; none of them is corrupt.
  const std::string path = std::string(PNEUMID_SOURCE_DIR) + "/tests/data/scipy_struct_cell.mat";
  const Dataset d = ReadMat(path);
  ASSERT_EQ(d.size(), 5);
  EXPECT_NEAR(d.time()[4], 0.4, 1e-15);
  EXPECT_DOUBLE_EQ(d.u()[1], std::sin(0.1));
  EXPECT_DOUBLE_EQ(d.y()[2], std::cos(0.2));
  MatReadOptions o;
  o.sample_time = 1.0;
  o.input_variables = {"i8"};
  o.output_variables = {"f"};
  ExpectError(path, o, {"has 1 samples but 'i8' has 3"});
  o.output_variables = {"i8"};
  const Dataset small = ReadMat(path, o);
  ASSERT_EQ(small.size(), 3);
  EXPECT_DOUBLE_EQ(small.y()[2], 3.0);
}

}  // namespace
}  // namespace pneumid
