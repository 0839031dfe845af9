// Model specs and the JSON form of a transfer function.
#include "pneumid/models/model_file.hpp"
#include "pneumid/models/model_file_scope.hpp"

#include <cstdio>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::ThrowsMessage;

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = std::string(PNEUMID_BINARY_DIR) + "/lti_model_io_" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(ModelIoTest, BuiltIns) {
  const TransferFunction arx = ParseModelSpec("arx-paper");
  EXPECT_DOUBLE_EQ(arx.Ts(), 0.01);
  EXPECT_DOUBLE_EQ(arx.num()[1], 0.03938);
  EXPECT_DOUBLE_EQ(arx.den()[3], -0.06021);
  const TransferFunction ct = ParseModelSpec("arx-paper-ct").Normalized();
  EXPECT_TRUE(ct.IsContinuous());
  EXPECT_NEAR(ct.den()[3] / 325421.7, 1.0, 2e-6);
  const TransferFunction f = ParseModelSpec(" fopdt-paper ");
  EXPECT_DOUBLE_EQ(f.DcGain(), 1.6);
  EXPECT_DOUBLE_EQ(f.delay(), 0.001);
  EXPECT_DOUBLE_EQ(f.den()[0], 0.245);
}

TEST(ModelIoTest, InlineSpecs) {
  const TransferFunction f = ParseModelSpec("fopdt:K=1.6,tau=0.245,theta=0.001");
  EXPECT_DOUBLE_EQ(f.DcGain(), 1.6);
  EXPECT_DOUBLE_EQ(f.delay(), 0.001);
  const TransferFunction s = ParseModelSpec("sopdt:K=2,tau1=1,tau2=0.5,theta=0.1");
  EXPECT_DOUBLE_EQ(s.DcGain(), 2.0);
  EXPECT_DOUBLE_EQ(s.den()[0], 0.5);
  const TransferFunction t = ParseModelSpec("tf:num=1 2,den=1;3;2");
  EXPECT_EQ(t.den().size(), 3);
  EXPECT_DOUBLE_EQ(t.DcGain(), 1.0);
  const TransferFunction d = ParseModelSpec("tf:num=0 0.5,den=1 -0.5,Ts=0.1,delay=0.2");
  EXPECT_EQ(d.DelaySamples(), 2);
  EXPECT_DOUBLE_EQ(d.DcGain(), 1.0);
}

TEST(ModelIoTest, JsonRoundTripIsMonic) {
  const TransferFunction g = TransferFunction::Continuous({2.0, 4.0}, {2.0, 6.0, 4.0}, 0.5);
  const nlohmann::json j = ToJson(g);
  EXPECT_EQ(j.at("den")[0], 1.0);
  EXPECT_EQ(j.at("num")[0], 1.0);
  EXPECT_EQ(j.at("Ts"), 0.0);
  EXPECT_EQ(j.at("delay"), 0.5);
  const TransferFunction back = TransferFunctionFromJson(j);
  EXPECT_DOUBLE_EQ(back.DcGain(), 1.0);
  EXPECT_DOUBLE_EQ(back.delay(), 0.5);
  EXPECT_THAT(
      [] {
        TransferFunctionFromJson({{"num", {1}}});
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("missing key 'den'")));
  EXPECT_THAT(
      [] {
        TransferFunctionFromJson({{"num", {1}}, {"den", {"a"}}});
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("'den' must contain only numbers")));
}

TEST(ModelIoTest, JsonFiles) {
  const std::string bare =
      WriteTemp("bare.json", R"({"num": [2], "den": [1, 1], "Ts": 0, "delay": 0.1})");
  EXPECT_DOUBLE_EQ(ParseModelSpec(bare).DcGain(), 2.0);
  const std::string list = WriteTemp("list.json", R"({"models": [
    {"method": "reaction-curve", "tf": {"num": [1.6], "den": [0.245, 1], "Ts": 0, "delay": 0.001}},
    {"method": "arx", "tf": {"num": [0, 0.5], "den": [1, -0.5], "Ts": 0.01, "delay": 0}}]})");
  EXPECT_DOUBLE_EQ(ParseModelSpec(list).DcGain(), 1.6);
  EXPECT_DOUBLE_EQ(ParseModelSpec(list + "#arx").Ts(), 0.01);
  EXPECT_THAT([&] { ParseModelSpec(list + "#oe"); },
              ThrowsMessage<DataError>(HasSubstr("no model with method 'oe'")));
  const std::string broken = WriteTemp("broken.json", "{\n  \"num\": [1,\n}");
  EXPECT_THAT([&] { ParseModelSpec(broken); },
              ThrowsMessage<DataError>(HasSubstr("broken.json:3:")));
  EXPECT_THAT([] { ParseModelSpec("/nonexistent/model.json"); },
              ThrowsMessage<DataError>(HasSubstr("/nonexistent/model.json: cannot open")));
}

// An identified discrete model whose continuous form is only its tustin
// approximation is read as identified (discrete, strictly proper); with an
// exact (zoh) continuous form the continuous one is read.
TEST(ModelIoTest, TustinOnlyModelsAreReadInDiscreteForm) {
  const std::string tustin = WriteTemp("tustin.json", R"json({"method": "arx",
    "tf": {"num": [0.1, 1, 100], "den": [1, 50, 100], "Ts": 0, "delay": 0},
    "discrete": {"num": [0, 0.5, 0.2], "den": [1, -0.5, 0.2], "Ts": 0.01, "delay": 0},
    "notes": ["continuous form by tustin d2c: no zoh equivalent (d2c zoh: pole at z = -0.3)"]})json");
  const TransferFunction g = ParseModelSpec(tustin);
  EXPECT_TRUE(g.IsDiscrete());
  EXPECT_DOUBLE_EQ(g.Ts(), 0.01);
  const std::string exact = WriteTemp("exact.json", R"({"method": "arx",
    "tf": {"num": [1], "den": [1, 1], "Ts": 0, "delay": 0},
    "discrete": {"num": [0, 0.5], "den": [1, -0.5], "Ts": 0.01, "delay": 0},
    "notes": ["fit by least squares"]})");
  EXPECT_TRUE(ParseModelSpec(exact).IsContinuous());
  // The typed key says it without a note, and wins over one.
  const std::string keyed = WriteTemp("keyed.json", R"json({"method": "arx",
    "tf": {"num": [0.1, 1, 100], "den": [1, 50, 100], "Ts": 0, "delay": 0},
    "discrete": {"num": [0, 0.5, 0.2], "den": [1, -0.5, 0.2], "Ts": 0.01, "delay": 0},
    "continuous_form": "tustin", "notes": ["fit by least squares"]})json");
  EXPECT_TRUE(ParseModelSpec(keyed).IsDiscrete());
  const std::string zoh = WriteTemp("zoh.json", R"json({"method": "arx",
    "tf": {"num": [1], "den": [1, 1], "Ts": 0, "delay": 0},
    "discrete": {"num": [0, 0.5], "den": [1, -0.5], "Ts": 0.01, "delay": 0},
    "continuous_form": "zoh", "notes": ["continuous form by tustin d2c: an old note"]})json");
  EXPECT_TRUE(ParseModelSpec(zoh).IsContinuous());
}

TEST(ModelIoTest, BadSpecsNameTheField) {
  EXPECT_THAT([] { ParseModelSpec("fopdt:K=1.6,tau=abc"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("key 'tau': not a finite number: 'abc'")));
  EXPECT_THAT([] { ParseModelSpec("fopdt:K=1.6"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("missing key 'tau'")));
  EXPECT_THAT([] { ParseModelSpec("fopdt:K=1,tau=1,zeta=2"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("unknown key 'zeta'")));
  EXPECT_THAT([] { ParseModelSpec("tf:num=1,den="); },
              ThrowsMessage<InvalidArgument>(HasSubstr("key 'den' has no values")));
  EXPECT_THAT([] { ParseModelSpec("fopdt:K=1,tau=-1"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("tau must be > 0")));
  EXPECT_THAT([] { ParseModelSpec("arx-papr"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("unknown model spec 'arx-papr'")));
  EXPECT_THAT([] { ParseModelSpec(""); }, ThrowsMessage<InvalidArgument>(HasSubstr("empty")));
  EXPECT_THAT([] { ParseModelSpec("fopdt:K=1,2,tau=1"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("key 'K' takes one number, got '1,2'")));
}

TEST(ModelIoTest, CommasInsideCoefficientLists) {
  // A bare number after key=value continues that key's list.
  const TransferFunction g = ParseModelSpec("tf:num=1,den=1,-1,Ts=0.1");
  EXPECT_EQ(g.den(), Eigen::Vector2d(1.0, -1.0));
  EXPECT_DOUBLE_EQ(g.num()(0), 1.0);  // num = [1] (padded to the length of den)
  EXPECT_DOUBLE_EQ(g.Ts(), 0.1);
  EXPECT_EQ(ParseModelSpec("tf:num=1 2,den=1;3;2").den(), Eigen::Vector3d(1.0, 3.0, 2.0));
}

TEST(ModelIoTest, BadModelFilesNameTheFile) {
  // A number beyond the range of double: the JSON library's overflow, with the file name.
  const std::string huge = WriteTemp("huge.json", R"({"num": [72e377], "den": [1, 1]})");
  EXPECT_THAT([&] { ParseModelSpec(huge); },
              ThrowsMessage<DataError>(AllOf(HasSubstr("huge.json"), HasSubstr("72e377"),
                                             Not(HasSubstr("[json.exception")))));
  const std::string dir = ::testing::TempDir();
  EXPECT_THAT([&] { ParseModelSpec(dir); },
              ThrowsMessage<DataError>(HasSubstr("is a directory, not a model file")));
  EXPECT_THAT([] { ParseModelSpec("."); },
              ThrowsMessage<DataError>(HasSubstr(".: is a directory, not a model file")));
}

}  // namespace
}  // namespace pneumid

namespace pneumid {
namespace {

// Read system calls of this process so far (Linux /proc/self/io).
long ReadCalls() {
  std::ifstream io("/proc/self/io");
  std::string key;
  long value = 0;
  while (io >> key >> value)
    if (key == "syscr:") return value;
  return -1;
}

void WriteModel(const std::string& path, const std::string& den) {
  std::ofstream(path) << R"({"num": [2.0], "den": [)" << den << R"(], "Ts": 0.0, "delay": 0.0})";
}

// The read system calls that `work` makes, less those of measuring them.
template <typename Work>
long ReadsOf(Work work) {
  const auto delta = [](auto f) {
    const long a = ReadCalls();
    f();
    return ReadCalls() - a;
  };
  return delta(work) - delta([] {});
}

// Inside a ModelFileScope a spec consulted again is not read again (no read
// system call), a file changed on disk is read again, and without a scope
// every call reads the file.
// A model document provided in memory reads as the file of its name inside
// the scope (the app's model objects), and is gone when the scope closes.
TEST(ModelIoTest, AScopeReadsModelDocumentsProvidedInMemory) {
  const std::string name = "pneumid-provided-model.json";
  const nlohmann::json document = nlohmann::json::parse(R"({"models": [
    {"method": "fit-p1d", "tf": {"num": [2], "den": [1, 1], "Ts": 0, "delay": 0},
     "input_map": {"u": [0, 50, 100], "y": [0, 40, 160]}}]})");
  EXPECT_THAT([&] { ModelFileScope::Provide(name, document); },
              ThrowsMessage<InvalidArgument>(HasSubstr("inside a ModelFileScope")));
  {
    const ModelFileScope scope;
    ModelFileScope::Provide(name, document);
    EXPECT_DOUBLE_EQ(ParseModelSpec(name + "#fit-p1d").DcGain(), 2.0);
    ASSERT_TRUE(ParseModelInputMap(name).has_value());
    EXPECT_DOUBLE_EQ(ReadStaticMap(name).Evaluate(100.0), 160.0);
    ASSERT_TRUE(ReadModelEntry(name).has_value());
    EXPECT_THAT([&] { ParseModelSpec(name + "#arx"); },
                ThrowsMessage<DataError>(HasSubstr("no model with method 'arx'")));
    EXPECT_THAT([&] { ModelFileScope::Provide("a#b", document); },
                ThrowsMessage<InvalidArgument>(HasSubstr("without '#'")));
  }
  // No such file once the scope has closed.
  EXPECT_ANY_THROW(ParseModelSpec(name));
  EXPECT_FALSE(ReadModelEntry(name).has_value());
}

TEST(ModelIoTest, AScopeReadsEachModelFileOnce) {
  if (ReadCalls() < 0) GTEST_SKIP() << "no /proc/self/io";
  const std::string path = ::testing::TempDir() + "pneumid_model_scope.json";
  WriteModel(path, "1.0, 1.0");
  {
    const ModelFileScope scope;
    EXPECT_GT(ReadsOf([&] { EXPECT_DOUBLE_EQ(ParseModelSpec(path).DcGain(), 2.0); }), 0);
    EXPECT_EQ(ReadsOf([&] {
                EXPECT_DOUBLE_EQ(ParseModelSpec(path).DcGain(), 2.0);
                EXPECT_FALSE(ParseModelInputMap(path).has_value());
                EXPECT_FALSE(ParseModelNarx(path).has_value());
                const ModelFileScope inner;  // nested: the outer scope's files
                EXPECT_DOUBLE_EQ(ParseModelSpec(path).DcGain(), 2.0);
              }),
              0);
    WriteModel(path, "1.0, 4.0");  // changed on disk: read again
    EXPECT_GT(ReadsOf([&] { EXPECT_DOUBLE_EQ(ParseModelSpec(path).DcGain(), 0.5); }), 0);
  }
  // No scope: every call reads the file.
  EXPECT_GT(ReadsOf([&] { EXPECT_DOUBLE_EQ(ParseModelSpec(path).DcGain(), 0.5); }), 0);
  EXPECT_GT(ReadsOf([&] { EXPECT_DOUBLE_EQ(ParseModelSpec(path).DcGain(), 0.5); }), 0);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace pneumid
