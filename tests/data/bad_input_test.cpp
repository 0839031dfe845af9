// Malformed and hostile input files: each is rejected quickly, with a message
// that says what is wrong and quotes user data only as a short excerpt.
#include <zlib.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/data/csv.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/data/matfile.hpp"
#include "test_files.hpp"

namespace pneumid {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::ThrowsMessage;

std::string Message(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  ADD_FAILURE() << "no exception";
  return "";
}

// --- MAT v5 files assembled byte by byte (MAT-File Format, level 5) ---------

void PutU32(std::string* s, std::uint32_t v) { s->append(reinterpret_cast<const char*>(&v), 4); }

std::string Pad8(std::string s) {
  s.resize((s.size() + 7) / 8 * 8, '\0');
  return s;
}

std::string Element(std::uint32_t type, const std::string& data) {
  std::string e;
  PutU32(&e, type);
  PutU32(&e, static_cast<std::uint32_t>(data.size()));
  return e + Pad8(data);
}

/// An miMATRIX element of class double with the given dimensions (as claimed)
/// and data.
std::string DoubleMatrix(const std::string& name, std::uint32_t rows, std::uint32_t cols,
                         const std::vector<double>& values) {
  std::string flags, dims, data;
  PutU32(&flags, 6);  // mxDOUBLE_CLASS
  PutU32(&flags, 0);
  PutU32(&dims, rows);
  PutU32(&dims, cols);
  data.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
  return Element(14, Element(6, flags) + Element(5, dims) + Element(1, name) + Element(9, data));
}

std::string MatHeader() {
  std::string h(116, ' ');
  std::memcpy(h.data(), "MATLAB 5.0 MAT-file, written by pneumid tests", 45);
  h.append(8, '\0');
  h.push_back('\x00');
  h.push_back('\x01');  // version 0x0100, little endian
  h += "IM";
  return h;
}

std::string Compress(const std::string& element) {
  uLongf size = compressBound(element.size());
  std::string out(size, '\0');
  compress(reinterpret_cast<Bytef*>(out.data()), &size,
           reinterpret_cast<const Bytef*>(element.data()), element.size());
  out.resize(size);
  std::string e;
  PutU32(&e, 15);
  PutU32(&e, static_cast<std::uint32_t>(out.size()));
  return e + out;
}

class BadInputTest : public ::testing::Test {
 protected:
  std::string Write(const std::string& name, const std::string& content) {
    return dir_.Write(name, content);
  }
  testing::TempDir dir_;
};

TEST(ExcerptTest, CapsLongTextAndEscapesControlBytes) {
  EXPECT_EQ(Excerpt("abc"), "abc");
  EXPECT_EQ(Excerpt(std::string(100, 'x'), 10), "xxxxxxxxxx... (100 bytes)");
  EXPECT_EQ(Excerpt(std::string("a\0b\x1b", 4)), "a\\x00b\\x1B");
  EXPECT_EQ(Excerpt("\xFF\xFEz"), "\\xFF\\xFEz");
  // Valid UTF-8 is kept, and never cut inside a character.
  EXPECT_EQ(Excerpt("T [\xC2\xB0"
                    "C]"),
            "T [\xC2\xB0"
            "C]");
  EXPECT_EQ(Excerpt("ab\xC2\xB0", 3), "ab... (4 bytes)");
  std::size_t bad = 0;
  EXPECT_TRUE(IsValidUtf8("F [N] \xE2\x82\xAC"));
  EXPECT_FALSE(IsValidUtf8("ok\xC0\xAF", &bad));
  EXPECT_EQ(bad, 2u);
  EXPECT_FALSE(IsValidUtf8("\xED\xA0\x80"));  // surrogate
}

TEST_F(BadInputTest, HugeCellIsQuotedAsAnExcerpt) {
  const std::string cell(10 << 20, 'z');
  const std::string path = Write("big.csv", "t,u,y\n0,1," + cell + "\n");
  const std::string m = Message([&] { ReadCsv(path); });
  EXPECT_THAT(m, AllOf(HasSubstr(path + ":2: column 'y': not a number: 'zzzz"),
                       HasSubstr(fmt::format("... ({} bytes)", cell.size()))));
  EXPECT_LT(m.size(), 300u);
}

TEST_F(BadInputTest, HugeColumnNameIsQuotedAsAnExcerpt) {
  const std::string name(1 << 16, 'n');
  const std::string path = Write("name.csv", "t,u," + name + "\n0,1,x\n");
  CsvReadOptions o;
  o.output_columns = {"2"};
  const std::string m = Message([&] { ReadCsv(path, o); });
  EXPECT_THAT(m, HasSubstr("... (65536 bytes)': not a number: 'x'"));
  EXPECT_LT(m.size(), 300u);
}

TEST_F(BadInputTest, Utf16FileIsReportedAsSuch) {
  std::string text = "\xFF\xFE";
  for (char c : std::string("t,u,y\n0,1,2\n")) {
    text.push_back(c);
    text.push_back('\0');
  }
  const std::string path = Write("utf16.csv", text);
  EXPECT_THAT([&] { ReadCsv(path); },
              ThrowsMessage<DataError>(AllOf(HasSubstr(path + ":1: the file is UTF-16LE text"),
                                             HasSubstr("save it as UTF-8"))));
  // Without a byte order mark, the NUL bytes give it away.
  const std::string no_bom = Write("utf16-nobom.csv", text.substr(2));
  EXPECT_THAT([&] { ReadCsv(no_bom); },
              ThrowsMessage<DataError>(
                  AllOf(HasSubstr(no_bom + ":1: NUL byte at offset 1"), HasSubstr("binary file"))));
}

TEST_F(BadInputTest, BinaryFileIsReportedAsBinary) {
  const std::string path = Write("data.csv", std::string("\x7f"
                                                         "ELF\x02\x01\x01\0\0\0",
                                                         10));
  EXPECT_THAT([&] { ReadCsv(path); },
              ThrowsMessage<DataError>(HasSubstr("NUL byte at offset 7: this is a binary file")));
}

TEST_F(BadInputTest, HeaderThatIsNotUtf8IsNamedWhenAColumnIsMissing) {
  // Latin-1 "Temperatur [\xB0C]": readable as long as the columns resolve.
  const std::string ok = Write("latin1.csv",
                               "t,u,y [\xB0"
                               "C]\n0,1,2\n1,1,3\n");
  EXPECT_EQ(ReadCsv(ok).size(), 2);
  const std::string path = Write("mojibake.csv", "\x8F\x90,\x91\n0,1\n");
  EXPECT_THAT([&] { ReadCsv(path); },
              ThrowsMessage<DataError>(AllOf(
                  HasSubstr("unknown time column 't'; available columns: '\\x8F\\x90'"),
                  HasSubstr("the header row is not valid UTF-8 text: byte 0x8F at offset 0"))));
}

TEST_F(BadInputTest, HeaderlessLongLineIsBoundedInTimeAndMessage) {
  std::string line;
  for (int i = 0; i < 300000; ++i) line += "1.5,";
  line += "2\n";
  const std::string path = Write("numbers.csv", line);
  const auto start = std::chrono::steady_clock::now();
  const std::string m = Message([&] { ReadCsv(path); });
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
  EXPECT_THAT(m, AllOf(HasSubstr(path + ":1: header row is 1200001 bytes long (at most 1048576)"),
                       HasSubstr("needs a first row of column names")));
  // Below the byte limit but above the column limit.
  line.resize(4 * 20000);
  line.back() = '\n';
  const std::string wide = Write("wide.csv", line);
  EXPECT_THAT([&] { ReadCsv(wide); },
              ThrowsMessage<DataError>(AllOf(
                  HasSubstr("header row has 20000 columns (delimiter ','), more than the 10000"),
                  HasSubstr("it holds numbers: is the header row missing?"))));
}

TEST_F(BadInputTest, ListOfAvailableColumnsIsCapped) {
  std::string header = "t";
  std::string row = "0";
  for (int i = 0; i < 500; ++i) {
    header += fmt::format(",c{}", i);
    row += ",1";
  }
  const std::string path = Write("many.csv", header + "\n" + row + "\n");
  const std::string m = Message([&] { ReadCsv(path); });
  EXPECT_THAT(m, AllOf(HasSubstr("unknown input column 'u'; available columns: 't', 'c0'"),
                       HasSubstr("'c18', ... (501 columns in all)"), Not(HasSubstr("c19"))));
}

TEST_F(BadInputTest, NumericFirstRowHintsAtAMissingHeader) {
  const std::string path = Write("noheader.csv", "0,1,2\n1,1,3\n");
  EXPECT_THAT([&] { ReadCsv(path); },
              ThrowsMessage<DataError>(
                  HasSubstr("(the first row holds numbers: is the header row missing?)")));
}

TEST_F(BadInputTest, MissingFileIsReportedBeforeTheExtension) {
  EXPECT_THAT([&] { LoadDataset("/nonexistent"); },
              ThrowsMessage<DataError>(HasSubstr("/nonexistent: cannot open: No such file")));
  EXPECT_THAT([&] { LoadDataset(dir_.Path("")); },
              ThrowsMessage<DataError>(HasSubstr("is a directory, not a data file")));
}

TEST_F(BadInputTest, HandBuiltMatFileReads) {
  // The builder itself is right: a well-formed file reads back.
  const std::string path = Write("ok.mat", MatHeader() + DoubleMatrix("t", 3, 1, {0, 1, 2}) +
                                               Compress(DoubleMatrix("u", 3, 1, {1, 1, 1})) +
                                               DoubleMatrix("y", 1, 3, {0, 2, 3}));
  const Dataset d = ReadMat(path);
  EXPECT_EQ(d.size(), 3);
  EXPECT_DOUBLE_EQ(d.y()[2], 3.0);
}

TEST_F(BadInputTest, TruncatedMatFileIsReportedAsTruncated) {
  const std::string full = MatHeader() + DoubleMatrix("t", 4, 1, {0, 1, 2, 3}) +
                           DoubleMatrix("u", 4, 1, {0, 1, 1, 1}) +
                           DoubleMatrix("y", 4, 1, {0, 1, 2, 3});
  const std::string path = Write("cut.mat", full.substr(0, full.size() - 20));
  EXPECT_THAT([&] { ReadMat(path); },
              ThrowsMessage<DataError>(
                  AllOf(HasSubstr("variable 3 ('y') needs"), HasSubstr("the file is truncated"))));
  // Cut inside a compressed variable.
  const std::string zfull = MatHeader() + DoubleMatrix("t", 4, 1, {0, 1, 2, 3}) +
                            Compress(DoubleMatrix("u", 4, 1, {0, 1, 1, 1}));
  const std::string zpath = Write("zcut.mat", zfull.substr(0, zfull.size() - 5));
  EXPECT_THAT([&] { ReadMat(zpath); },
              ThrowsMessage<DataError>(
                  AllOf(HasSubstr("variable 2 ('u') needs"), HasSubstr("the file is truncated"))));
  // Cut inside the tag of the next variable.
  const std::string tpath = Write("tagcut.mat", full.substr(0, 128 + 96 + 4));
  EXPECT_THAT([&] { ReadMat(tpath); },
              ThrowsMessage<DataError>(HasSubstr("ends inside the tag of variable 2")));
}

TEST_F(BadInputTest, MatVariableClaimingHugeDimensionsIsRejectedQuickly) {
  const auto start = std::chrono::steady_clock::now();
  const std::string path =
      Write("huge.mat", MatHeader() + DoubleMatrix("t", 0x7FFFFFFF, 0x7FFFFFFF, {0, 1}));
  EXPECT_THAT([&] { ReadMat(path); },
              ThrowsMessage<DataError>(
                  AllOf(HasSubstr("variable 1 ('t') claims dimensions 2147483647x2147483647"),
                        HasSubstr("the file is corrupt"))));
  // The same inside a compressed variable, and a cell of 2^31 elements.
  std::string flags, dims;
  PutU32(&flags, 1);  // mxCELL_CLASS
  PutU32(&flags, 0);
  PutU32(&dims, 0x7FFFFFFF);
  PutU32(&dims, 1);
  const std::string cell = Element(14, Element(6, flags) + Element(5, dims) + Element(1, "c"));
  const std::string zpath = Write("zhuge.mat", MatHeader() + Compress(cell));
  EXPECT_THAT([&] { ReadMat(zpath); },
              ThrowsMessage<DataError>(HasSubstr("variable 1 ('c') claims dimensions")));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
}

TEST_F(BadInputTest, MatDimensionsOfTheWrongTypeAreRejected) {
  // Found by mat_fuzz: a dimensions tag of type 10 over 50 bytes, which matio
  // reads as int32 dimensions anyway (1.8 GB and 6 s for a 464-byte file).
  std::string flags, dims = "\x01\x00\x00\x00\xfelink access to nothing here, at all!!!!!!!!";
  PutU32(&flags, 6);  // mxDOUBLE_CLASS
  PutU32(&flags, 0);
  const std::string bad = Element(14, Element(6, flags) + Element(10, dims) + Element(1, "t") +
                                          Element(9, std::string(8, '\0')));
  const std::string path = Write("dims_type.mat", MatHeader() + bad);
  EXPECT_THAT([&] { ReadMat(path); },
              ThrowsMessage<DataError>(HasSubstr(
                  "variable 1: its dimensions element has type 10, not miINT32 (5): the file is "
                  "corrupt")));
  const std::string zpath = Write("zdims_type.mat", MatHeader() + Compress(bad));
  EXPECT_THAT([&] { ReadMat(zpath); }, ThrowsMessage<DataError>(HasSubstr("not miINT32 (5)")));
}

TEST_F(BadInputTest, MatArrayFlagsOfAnotherSizeAreRejected) {
  // Found by mat_fuzz: array flags claiming 50 bytes; matio reads 8 whatever
  // the tag says, so it met a dimensions tag of type 10 and a name claiming
  // 1.8 GB where this check saw valid dimensions (11 s for a 464-byte file).
  std::string flags, dims;
  PutU32(&flags, 1);  // mxCELL_CLASS
  PutU32(&flags, 0);
  std::string hidden = flags;
  PutU32(&hidden, 10);  // what matio takes for the dimensions tag
  PutU32(&hidden, 50);
  PutU32(&hidden, 1);
  PutU32(&hidden, 0x6e696cfeu);
  hidden.resize(50, '\0');
  PutU32(&dims, 1);
  PutU32(&dims, 1);
  const std::string bad = Element(14, Element(6, hidden) + Element(5, dims) + Element(1, "") +
                                          Element(9, std::string(8, '\0')));
  for (const auto& [name, body] :
       {std::pair<std::string, std::string>{"flags.mat", bad}, {"zflags.mat", Compress(bad)}}) {
    const auto start = std::chrono::steady_clock::now();
    const std::string path = Write(name, MatHeader() + body);
    EXPECT_THAT([&] { ReadMat(path); },
                ThrowsMessage<DataError>(AllOf(
                    HasSubstr("its array flags element has type 6 and 50 bytes, not miUINT32 (6) "
                              "and 8 bytes"),
                    HasSubstr("the file is corrupt"))))
        << name;
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2)) << name;
  }
}

TEST_F(BadInputTest, MatFunctionClassDimensionsAreCheckedLikeNumericOnes) {
  // Found by mat_fuzz: a function-class (16) array claiming 1296629765x1
  // elements in 88 bytes; matio allocated 10 GB of doubles for it.
  std::string flags, dims;
  PutU32(&flags, 16);  // mxFUNCTION_CLASS
  PutU32(&flags, 0);
  PutU32(&dims, 1296629765);
  PutU32(&dims, 1);
  const std::string bad = Element(14, Element(6, flags) + Element(5, dims) + Element(1, "t") +
                                          Element(9, std::string(40, '\0')));
  const std::string path = Write("function_dims.mat", MatHeader() + bad);
  EXPECT_THAT([&] { ReadMat(path); },
              ThrowsMessage<DataError>(AllOf(HasSubstr("claims dimensions 1296629765x1"),
                                             HasSubstr("the file is corrupt"))));
}

TEST_F(BadInputTest, MatSmallElementClaimingMoreThanItsTagIsCorrupt) {
  // Found by mat_fuzz: in a compressed variable, a small-format dimensions
  // element (type 5) claiming 2048 bytes; matio read 512 "dimensions" past it
  // and allocated 2.5 GB.
  std::string flags, dims;
  PutU32(&flags, 6);  // mxDOUBLE_CLASS
  PutU32(&flags, 0);
  PutU32(&dims, (2048u << 16) | 5u);  // small element: 2048 bytes of miINT32
  PutU32(&dims, 1);
  const std::string bad =
      Element(14, Element(6, flags) + dims + Element(1, "t") + Element(9, std::string(8, '\0')));
  for (const auto& [name, body] :
       {std::pair<std::string, std::string>{"small.mat", bad}, {"zsmall.mat", Compress(bad)}}) {
    const std::string path = Write(name, MatHeader() + body);
    EXPECT_THAT([&] { ReadMat(path); }, ThrowsMessage<DataError>(AllOf(
                                            HasSubstr("a small data element (type 5) claims 2048 "
                                                      "bytes"),
                                            HasSubstr("the file is corrupt"))))
        << name;
  }
}

TEST_F(BadInputTest, MatSmallFormatDimensionsAreCorrupt) {
  // Found by mat_fuzz: in a compressed variable, a small-format dimensions
  // element holding 4 bytes (0x26000000); matio took that word for the size of
  // the dimensions and asked for 2.5 GB.
  std::string flags, dims;
  PutU32(&flags, 6);  // mxDOUBLE_CLASS
  PutU32(&flags, 0);
  PutU32(&dims, (4u << 16) | 5u);  // small element: 4 bytes of miINT32
  PutU32(&dims, 0x26000000u);
  const std::string bad =
      Element(14, Element(6, flags) + dims + Element(1, "t") + Element(9, std::string(8, '\0')));
  for (const auto& [name, body] :
       {std::pair<std::string, std::string>{"small4.mat", bad}, {"zsmall4.mat", Compress(bad)}}) {
    const std::string path = Write(name, MatHeader() + body);
    EXPECT_THAT([&] { ReadMat(path); },
                ThrowsMessage<DataError>(
                    AllOf(HasSubstr("its dimensions element is in the small data element "
                                    "format (4 bytes)"),
                          HasSubstr("the file is corrupt"))))
        << name;
  }
}

TEST_F(BadInputTest, MatElementLargerThanItsCompressedArrayIsCorrupt) {
  // Only the start of a compressed array is inflated; an element there that
  // claims more than its array claims is corrupt even though its bytes are
  // not all present.
  std::string flags;
  PutU32(&flags, 6);  // mxDOUBLE_CLASS
  PutU32(&flags, 0);
  std::string body = Element(6, flags);
  PutU32(&body, 5);            // miINT32 dimensions
  PutU32(&body, 0x4C000000u);  // claiming 1.3 GB
  PutU32(&body, 2);
  PutU32(&body, 2);
  std::string matrix;
  PutU32(&matrix, 14);
  PutU32(&matrix, 200);  // the array claims 200 bytes; 32 follow
  matrix += body;
  const std::string path = Write("zroom.mat", MatHeader() + Compress(matrix));
  EXPECT_THAT(
      [&] { ReadMat(path); },
      ThrowsMessage<DataError>(AllOf(HasSubstr("variable 1: an element claims 1275068416 bytes"),
                                     HasSubstr("more than the 176 bytes left in its "
                                               "array: the file is corrupt"))));
}

TEST_F(BadInputTest, MatEmptyVariableWithAHugeDimensionIsCorrupt) {
  // Found by mat_fuzz: a 22-byte Level 4 file whose variable claims 0 x
  // 1415643158 doubles; no data, but matio walked the columns for 11 s.
  const std::string v4("\0\0\0\0\0\0\0\0\x16\0\x61\x54\0\0\0\0\x02\0\0\0\0\x24", 22);
  const std::string path = Write("v4_empty.mat", v4);
  MatReadOptions by_index;
  by_index.time_variable = "0";
  EXPECT_THAT([&] { ReadMat(path, by_index); },
              ThrowsMessage<DataError>(AllOf(HasSubstr("variable '' is empty (0x1415643158 "
                                                       "double): it holds no time samples"))));
}

TEST_F(BadInputTest, MatEmptyVariableMakesNoChannelPerColumn) {
  // Found by mat_fuzz: a Level 4 variable '2' of 0 x 1000000 doubles, selected
  // by name, became a million empty channels (400 MB) before its length was
  // checked; a larger claim went beyond 2 GB.
  const std::string v4("\0\0\0\0\0\0\0\0\x40\x42\x0f\0\0\0\0\0\x02\0\0\0\x32\0", 22);
  const std::string path = Write("v4_empty_named.mat", v4);
  MatReadOptions by_name;
  by_name.time_variable = "2";
  EXPECT_THAT([&] { ReadMat(path, by_name); },
              ThrowsMessage<DataError>(
                  HasSubstr("variable '2' is empty (0x1000000 double): it holds no time samples")));
}

TEST_F(BadInputTest, MatVariableWithMoreColumnsThanChannelsIsRejected) {
  // A 2 x 1001 variable selected whole would be 1001 channels of 2 samples:
  // samples stored along the columns, or a corrupt header.
  std::string v4;
  for (std::uint32_t h : {0u, 2u, 1001u, 0u, 2u}) PutU32(&v4, h);
  v4 += std::string("u\0", 2);
  v4 += std::string(2 * 1001 * sizeof(double), '\0');
  const std::string path = Write("wide4.mat", v4);
  MatReadOptions o;
  o.time_variable = "";
  o.sample_time = 0.1;
  o.input_variables = {"u"};
  o.output_variables = {};
  EXPECT_THAT([&] { ReadMat(path, o); },
              ThrowsMessage<DataError>(HasSubstr(
                  "input variable 'u' (2x1001 double) would give 1001 channels, more than 1000: "
                  "store samples along the rows (N x k), or select one column with 'u:K'")));
  o.input_variables = {"u:1000"};
  EXPECT_EQ(ReadMat(path, o).size(), 2);
}

TEST_F(BadInputTest, MatLevel4HeaderIsReadInTheByteOrderItsTypeDeclares) {
  // A Level 4 header's fields follow the byte order that the M digit of its
  // type declares (0 little-endian, 1 big-endian), as matio reads them.
  auto be32 = [](std::string* s, std::uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8)
      s->push_back(static_cast<char>((v >> shift) & 0xFF));
  };
  MatReadOptions o;
  o.input_variables = {};
  o.output_variables = {"y"};
  o.sample_time = 0.1;
  // Big-endian throughout (type 1000: IEEE big-endian doubles): reads.
  std::string big;
  for (std::uint32_t h : {1000u, 3u, 1u, 0u, 2u}) be32(&big, h);
  big += std::string("y\0", 2);
  for (double v : {0.5, 1.5, 2.5}) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, sizeof(bits));
    be32(&big, static_cast<std::uint32_t>(bits >> 32));
    be32(&big, static_cast<std::uint32_t>(bits));
  }
  const Dataset d = ReadMat(Write("big4.mat", big), o);
  ASSERT_EQ(d.size(), 3);
  EXPECT_EQ(d.outputs()(2, 0), 2.5);
  // Found by mat_fuzz: a big-endian header whose type (2) declares
  // little-endian data; matio read the name length 123 as 0x7B000000 and
  // allocated 2 GB for it.
  std::string mixed;
  for (std::uint32_t h : {2u, 1u, 3u, 0u, 123u}) be32(&mixed, h);
  mixed += std::string(122, 'x') + std::string(1, '\0') + std::string(24, '\0');
  EXPECT_THAT([&] { ReadMat(Write("mixed4.mat", mixed), o); },
              ThrowsMessage<DataError>(AllOf(HasSubstr("variable 1 ('xxxxxxxx"),
                                             HasSubstr("claims 16777216x50331648"),
                                             HasSubstr("the file is truncated or corrupt"))));
}

TEST_F(BadInputTest, MatVariableOfZeroBytesIsCorrupt) {
  // Found by mat_fuzz: a variable whose miMATRIX tag claims 0 bytes, followed
  // by more elements. matio reads the variable's flags, dimensions and name
  // from those, and took an miINT32 claiming 0x65000001 bytes as dimensions
  // (3.4 GB); an array of 0 bytes is only an empty cell element or field.
  std::string flags;
  PutU32(&flags, 6);
  PutU32(&flags, 0);
  std::string dims;
  PutU32(&dims, 5);
  PutU32(&dims, 0x65000001u);
  std::string body;
  PutU32(&body, 14);
  PutU32(&body, 0);
  body += Element(6, "") + Element(5, dims);
  const std::string path = Write("zero.mat", MatHeader() + body);
  EXPECT_THAT([&] { ReadMat(path); },
              ThrowsMessage<DataError>(HasSubstr(
                  "variable 1: an array of 0 bytes, without the flags, dimensions and name every "
                  "variable has: the file is corrupt")));
}

TEST_F(BadInputTest, MatStructContentsMustBeArrays) {
  // Found by mat_fuzz: a struct whose field holds an element of another type
  // than miMATRIX; matio fails on it and leaks the fields it has read.
  auto structure = [](const std::string& content) {
    std::string flags, dims, body;
    PutU32(&flags, 2);  // mxSTRUCT_CLASS
    PutU32(&flags, 0);
    PutU32(&dims, 1);
    PutU32(&dims, 1);
    body = Element(6, flags) + Element(5, dims) + Element(1, "s");
    PutU32(&body, (4u << 16) | 5u);  // field name length 8, small miINT32
    PutU32(&body, 8);
    body += Element(1, std::string("a\0\0\0\0\0\0\0", 8)) + content;
    return Element(14, body);
  };
  const std::string good =
      Write("struct_ok.mat", MatHeader() + structure(DoubleMatrix("", 1, 1, {2.0})) +
                                 DoubleMatrix("y", 3, 1, {0, 1, 2}));
  MatReadOptions o;
  o.input_variables = {};
  o.output_variables = {"y"};
  o.sample_time = 0.1;
  EXPECT_EQ(ReadMat(good, o).size(), 3);
  const std::string bad =
      Write("struct_bad.mat", MatHeader() + structure(Element(9, std::string(8, '\0'))) +
                                  DoubleMatrix("y", 3, 1, {0, 1, 2}));
  EXPECT_THAT([&] { ReadMat(bad, o); },
              ThrowsMessage<DataError>(HasSubstr(
                  "variable 1 ('s'): element 1 of its struct contents has type 9, not miMATRIX "
                  "(14): the file is corrupt")));
}

TEST_F(BadInputTest, MatNonNumericVariablesNeverReachMatio) {
  // Found by mat_fuzz: a function-handle variable holding a nested array of 0
  // columns; matio failed inside it and leaked what it had read. Cell arrays,
  // structs, objects and function handles are listed from the scan and left
  // out of what matio reads; the numeric variables around them still read.
  std::string flags, dims, body;
  PutU32(&flags, 16);  // mxFUNCTION_CLASS
  PutU32(&flags, 0);
  PutU32(&dims, 1);
  PutU32(&dims, 2);
  body = Element(6, flags) + Element(5, dims) + Element(1, "f");
  body += DoubleMatrix("", 1, 0, {});
  const std::string path =
      Write("function.mat", MatHeader() + DoubleMatrix("t", 3, 1, {0, 1, 2}) + Element(14, body) +
                                DoubleMatrix("y", 3, 1, {4, 5, 6}));
  MatReadOptions o;
  o.time_variable = "t";
  o.input_variables = {};
  o.output_variables = {"y"};
  const Dataset d = ReadMat(path, o);
  ASSERT_EQ(d.size(), 3);
  EXPECT_EQ(d.outputs()(2, 0), 6.0);
  o.output_variables = {"f"};
  EXPECT_THAT([&] { ReadMat(path, o); },
              ThrowsMessage<DataError>(HasSubstr(
                  "variable 'f' (function handle): output data must be a real numeric array")));
  o.output_variables = {"z"};
  EXPECT_THAT([&] { ReadMat(path, o); },
              ThrowsMessage<DataError>(
                  HasSubstr("available variables: 't' (3x1 double), 'f' (1x2 function handle), "
                            "'y' (3x1 double)")));
  // Found by mat_fuzz: a class number beyond the format's 17 is no matio class.
  std::string odd_flags;
  PutU32(&odd_flags, 200);
  PutU32(&odd_flags, 0);
  const std::string odd = Write(
      "class200.mat",
      MatHeader() +
          Element(14, Element(6, odd_flags) + Element(5, dims) + Element(1, "q") + Element(9, "")) +
          DoubleMatrix("y", 3, 1, {4, 5, 6}));
  o.time_variable = "";
  o.sample_time = 0.1;
  o.output_variables = {"q"};
  EXPECT_THAT([&] { ReadMat(odd, o); },
              ThrowsMessage<DataError>(HasSubstr("variable 'q' (unknown class): output data must "
                                                 "be a real numeric array")));
}

TEST_F(BadInputTest, MatRepeatedVariableNameIsRejected) {
  // Level-4 header: type 0 (little-endian double), rows, columns, real, name length.
  auto v4 = [](const std::string& name, const std::vector<double>& values) {
    std::string s;
    for (std::uint32_t h : {0u, static_cast<std::uint32_t>(values.size()), 1u, 0u,
                            static_cast<std::uint32_t>(name.size() + 1)}) {
      PutU32(&s, h);
    }
    s += name;
    s += '\0';
    s.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
    return s;
  };
  MatReadOptions o;
  o.input_variables = {};
  o.output_variables = {"y"};
  o.sample_time = 0.1;
  const std::string ok = Write("y4.mat", v4("y", {0, 1, 2}) + v4("z", {5, 6}));
  EXPECT_EQ(ReadMat(ok, o).size(), 3);
  // matio reads the first 'y'; which one the user meant, the file cannot say.
  const std::string twice = Write("yy4.mat", v4("y", {0, 1, 2}) + v4("y", {5, 6}));
  EXPECT_THAT([&] { ReadMat(twice, o); },
              ThrowsMessage<DataError>(
                  AllOf(HasSubstr("yy4.mat: variable name 'y' appears 2 times in the file "
                                  "(variables 1, 2)"),
                        HasSubstr("output data"))));
  // Found by mat_fuzz: a 44-byte Level 4 file with a sparse variable claiming
  // 1073754112 x 0 and a 0 x 22 double, both named ''. The double was size
  // checked, but matio read the sparse one by the shared name (a 4 GB malloc).
  const std::string fuzz(
      "\x20\0\0\0\0\x30\0\x40\0\0\0\0\0\0\0\0\x02\0\0\0\0\x24\0\0"
      "\0\0\0\0\0\0\x16\0\0\0\0\0\0\0\x02\0\0\0\0\0",
      44);
  const std::string path = Write("v4_repeated_name.mat", fuzz);
  MatReadOptions by_index;
  by_index.time_variable = "0";
  EXPECT_THAT([&] { ReadMat(path, by_index); },
              ThrowsMessage<DataError>(HasSubstr("variable name '' appears 2 times")));
}

TEST_F(BadInputTest, MatVariableListIsCappedAndLongNamesAreExcerpts) {
  std::string file = MatHeader();
  for (int i = 0; i < 30; ++i) file += DoubleMatrix(fmt::format("v{}", i), 1, 1, {1.0});
  file += DoubleMatrix(std::string(300, 'n'), 1, 1, {1.0});
  const std::string path = Write("many.mat", file);
  const std::string m = Message([&] { ReadMat(path); });
  EXPECT_THAT(
      m,
      AllOf(HasSubstr("unknown time variable 't'; available variables: 'v0' (1x1 double)"),
            HasSubstr("'v19' (1x1 double), ... (31 variables in all)"), Not(HasSubstr("'v20'"))));
  MatReadOptions o;
  o.sample_time = 0.01;
  o.input_variables = {};
  o.output_variables = {"0"};
  EXPECT_THAT(
      [&] { ReadMat(path, o); },
      ThrowsMessage<DataError>(HasSubstr("exactly one numeric matrix variable, this one has 31")));
  // Reading a variable with a 300-character name quotes it as an excerpt.
  std::string cell_flags;
  PutU32(&cell_flags, 1);  // mxCELL_CLASS: not numeric
  PutU32(&cell_flags, 0);
  std::string dims;
  PutU32(&dims, 1);
  PutU32(&dims, 1);
  const std::string name(300, 'c');
  const std::string cell = Element(14, Element(6, cell_flags) + Element(5, dims) +
                                           Element(1, name) + DoubleMatrix("", 1, 1, {1}));
  const std::string cpath = Write("cell.mat", MatHeader() + cell);
  o.output_variables = {name};
  EXPECT_THAT([&] { ReadMat(cpath, o); },
              ThrowsMessage<DataError>(AllOf(HasSubstr("... (300 bytes)' (cell)"),
                                             Not(HasSubstr(std::string(41, 'c'))))));
}

TEST_F(BadInputTest, MatV4VariableLargerThanTheFileIsRejected) {
  // Level-4 header: type 0 (little-endian double), rows, columns, real, name length.
  auto v4 = [](std::uint32_t rows, const std::vector<double>& values) {
    std::string s;
    for (std::uint32_t h : {0u, rows, 1u, 0u, 2u}) PutU32(&s, h);
    s += std::string("t\0", 2);
    s.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
    return s;
  };
  const std::string ok = Write("ok4.mat", v4(3, {0, 1, 2}));
  MatReadOptions o;
  o.input_variables = {};
  o.output_variables = {"t"};
  EXPECT_EQ(ReadMat(ok, o).size(), 3);
  const auto start = std::chrono::steady_clock::now();
  const std::string path = Write("huge4.mat", v4(1000000000, {0, 1, 2}));
  EXPECT_THAT([&] { ReadMat(path, o); },
              ThrowsMessage<DataError>(AllOf(HasSubstr("variable 1 ('t') claims 1000000000x1"),
                                             HasSubstr("truncated or corrupt"))));
  // A second variable whose header is garbage (found by mat_fuzz: matio
  // allocated the name length it claims).
  std::string garbage = v4(3, {0, 1, 2});
  for (std::uint32_t h : {0u, 5u, 0x147b0000u, 0x7ae147aeu, 0x147b3f84u}) PutU32(&garbage, h);
  const std::string bad = Write("bad4.mat", garbage + std::string(64, '\0'));
  EXPECT_THAT([&] { ReadMat(bad, o); },
              ThrowsMessage<DataError>(AllOf(HasSubstr("variable 2 at offset 46: invalid header"),
                                             HasSubstr("imaginary flag 2061584302"))));
  // A v4 file whose bytes 126-127 happen to read "MI" without the v5 version
  // 0x0100 at 124 (found by mat_fuzz): matio reads it as v4, so it is checked as v4.
  std::string mi = v4(1000000000, {0, 1, 2});
  mi.resize(128, ' ');
  mi.replace(124, 4, "02MI");
  const std::string mi_path = Write("mi4.mat", mi);
  EXPECT_THAT([&] { ReadMat(mi_path, o); },
              ThrowsMessage<DataError>(AllOf(HasSubstr("variable 1 ('t') claims 1000000000x1"),
                                             HasSubstr("truncated or corrupt"))));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
}

TEST_F(BadInputTest, ExtremeValuesAreNamedWithTheColumnAndRange) {
  Eigen::VectorXd t(4), u(4), y(4);
  t << 0, 1, 2, 3;
  u << 0, 1, 1, 1;
  y << 0, 1e308, -1e308, 1e308;
  Dataset big(t, u, y, {{"p", "bar"}}, {{"F", "N"}});
  big.set_source("big.csv");
  EXPECT_THAT([&] { big.RequireNumericScale(); },
              ThrowsMessage<DataError>(AllOf(HasSubstr("big.csv: output column 'F'"),
                                             HasSubstr("values range from -1e+308 to 1e+308"),
                                             HasSubstr("overflow"))));
  y << 0, 1e-300, 2e-300, 2e-300;
  const Dataset tiny(t, u, y);
  EXPECT_THAT(
      [&] { tiny.RequireNumericScale(); },
      ThrowsMessage<DataError>(AllOf(HasSubstr("dataset: output column 'y'"),
                                     HasSubstr("a spread of 2e-300"), HasSubstr("extreme scale"))));
  y << 0, 1, 2, 2;
  EXPECT_NO_THROW(Dataset(t, u, y).RequireNumericScale());
  // Constant columns (no step) are left to the methods to diagnose.
  y.setConstant(1e-300);
  EXPECT_NO_THROW(Dataset(t, u, y).RequireNumericScale());
}

}  // namespace
}  // namespace pneumid
