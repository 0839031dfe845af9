// JSON form of identified models: the keys of the model files written by
// `pneumid identify -o` (a file format read back by --model FILE), typed
// parameters that survive the round trip, and errors that name the key.
#include "pneumid/identify/identified_model_io.hpp"

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/identify.hpp"
#include "pneumid/lti/model_io.hpp"
#include "step_test_util.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// One model as `pneumid identify --json` wrote it before the parameters were
// typed (numbers, integers, vectors and rows).
const char* kWritten = R"({
  "method": "n4sid", "structure": "SS",
  "params": {"A": [[0.5, 0.1], [0.0, 0.25]], "K": 1.6, "Ts": 0.01, "a": [1.0, -0.6],
             "nk": 1, "nks": [1, 2], "order": 2},
  "param_std": {"K": 0.01},
  "tf": {"num": [0.2, 0.0], "den": [1.0, -0.8], "Ts": 0.01, "delay": 0.0},
  "discrete": {"num": [0.2, 0.0], "den": [1.0, -0.8], "Ts": 0.01, "delay": 0.0},
  "fit_percent": 91.5, "iae": 0.25, "notes": ["a note"]})";

TEST(IdentifiedModelIoTest, ReadsAndWritesTheModelFileForm) {
  const nlohmann::json written = nlohmann::json::parse(kWritten);
  const IdentifiedModel m = IdentifiedModelFromJson(written);
  EXPECT_EQ(m.method, "n4sid");
  EXPECT_DOUBLE_EQ(m.params.Scalar("K"), 1.6);
  EXPECT_EQ(std::get<int>(m.params.at("nk")), 1);
  EXPECT_EQ(std::get<int>(m.params.at("order")), 2);
  EXPECT_EQ(std::get<std::vector<int>>(m.params.at("nks")), (std::vector<int>{1, 2}));
  EXPECT_EQ(m.params.Vector("a"), (std::vector<double>{1.0, -0.6}));
  EXPECT_EQ(std::get<std::vector<std::vector<double>>>(m.params.at("A"))[1][1], 0.25);
  EXPECT_DOUBLE_EQ(m.param_std.Scalar("K"), 0.01);
  ASSERT_TRUE(m.discrete.has_value());
  EXPECT_EQ(m.notes, std::vector<std::string>{"a note"});
  // Written back: the same keys and values (integers stay integers), plus the
  // keys added since: operating point, termination and flags, with the values
  // an older file implies.
  nlohmann::json expected = written;
  expected["operating_point"] = {{"u0", 0.0}, {"y0", 0.0}};
  expected["termination"] = "convergence";
  expected["flags"] = nlohmann::json::array();
  EXPECT_EQ(ToJson(m), expected);
  EXPECT_EQ(ToJson(m)["params"]["nk"].dump(), "1");
}

TEST(IdentifiedModelIoTest, RoundTripsOperatingPointFlagsAndValidationFit) {
  IdentifiedModel m;
  m.method = "fit-p1d";
  m.structure = "P1D";
  m.params = {{"K", 1.5}, {"y0", 0.25}};
  m.tf = TransferFunction::Fopdt(1.5, 0.2, 0.01);
  m.u0 = 0.61;
  m.y0 = 0.25;
  m.termination = Termination::kNoConvergence;
  m.validation_fit_percent = 88.5;
  m.flags = {{ModelFlag::kNyquistPole, "pole at z = -0.97"},
             {ModelFlag::kResidualsNotWhite, "Q = 80 > 44"}};
  const IdentifiedModel back = IdentifiedModelFromJson(ToJson(m));
  EXPECT_EQ(back.u0, 0.61);
  EXPECT_EQ(back.y0, 0.25);
  EXPECT_EQ(back.termination, Termination::kNoConvergence);
  EXPECT_EQ(back.validation_fit_percent, 88.5);
  EXPECT_EQ(back.flags, m.flags);
  // A file without an operating point takes y0 from a process model's offset.
  nlohmann::json old = ToJson(m);
  old.erase("operating_point");
  EXPECT_EQ(IdentifiedModelFromJson(old).y0, 0.25);
  EXPECT_EQ(IdentifiedModelFromJson(old).u0, 0.0);
  old["flags"] = {{{"flag", "bogus"}}};
  EXPECT_THAT([&] { IdentifiedModelFromJson(old); },
              ThrowsMessage<InvalidArgument>(HasSubstr("unknown model flag 'bogus'")));
  old["flags"] = nlohmann::json::array();
  old["operating_point"] = {{"u0", "x"}};
  EXPECT_THAT([&] { IdentifiedModelFromJson(old); },
              ThrowsMessage<InvalidArgument>(HasSubstr("operating_point.u0")));
}

TEST(IdentifiedModelIoTest, ModelFilesOfIdentifyStayReadableAsModelSpecs) {
  const Dataset d = testing::LoadSynthetic("fopdt");
  const IdentifiedModel rc = Identify("reaction-curve", d);
  const IdentifiedModel arx = Identify("arx", d);
  const nlohmann::json j = {{"models", {ToJson(arx), ToJson(rc)}}};
  for (const char* key : {"method", "structure", "params", "tf", "fit_percent", "iae"}) {
    EXPECT_TRUE(j["models"][1].contains(key)) << key;
  }
  for (const char* key : {"K", "tau", "theta", "t63"}) {
    EXPECT_TRUE(j["models"][1]["params"][key].is_number_float()) << key;
  }
  for (const char* key : {"a", "b", "nk", "Ts"}) EXPECT_TRUE(j["models"][0]["params"].contains(key));
  EXPECT_TRUE(j["models"][0]["params"]["nk"].is_number_integer());
  const auto path = std::filesystem::temp_directory_path() / "pneumid_identified_model_io.json";
  std::ofstream(path) << j.dump(2);
  // Without a '#method' the file's first model (the ARX) is read.
  const TransferFunction first = ParseModelSpec(path.string());
  const TransferFunction named = ParseModelSpec(path.string() + "#arx");
  EXPECT_EQ(first.IsDiscrete(), named.IsDiscrete());
  ASSERT_EQ(first.num().size(), named.num().size());
  ASSERT_EQ(first.den().size(), named.den().size());
  EXPECT_EQ(first.num(), named.num());
  EXPECT_EQ(first.den(), named.den());
  const TransferFunction fopdt = ParseModelSpec(path.string() + "#reaction-curve");
  EXPECT_NEAR(fopdt.DcGain(), rc.params.Scalar("K"), 1e-9);
  EXPECT_NEAR(fopdt.delay(), rc.params.Scalar("theta"), 1e-12);
  std::filesystem::remove(path);
  // And back to typed models.
  EXPECT_EQ(IdentifiedModelFromJson(ToJson(rc)).params, rc.params);
  EXPECT_EQ(IdentifiedModelFromJson(ToJson(arx)).params, arx.params);
}

TEST(IdentifiedModelIoTest, ErrorsNameTheKey) {
  EXPECT_THAT([] { ModelParamsFromJson(nlohmann::json{{"K", "big"}}); },
              ThrowsMessage<InvalidArgument>(HasSubstr("parameter 'K'")));
  EXPECT_THAT([] { ModelParamsFromJson(nlohmann::json{{"a", {1.0, "x"}}}); },
              ThrowsMessage<InvalidArgument>(HasSubstr("parameter 'a'")));
  nlohmann::json no_tf = nlohmann::json::parse(kWritten);
  no_tf.erase("tf");
  EXPECT_THAT([&] { IdentifiedModelFromJson(no_tf); },
              ThrowsMessage<InvalidArgument>(HasSubstr("'tf'")));
}

TEST(ModelParamsTest, TypedAccessors) {
  ModelParams p{{"K", 2.0}, {"n", 3}, {"a", std::vector<double>{1.0, 0.5}}};
  EXPECT_DOUBLE_EQ(p.Scalar("K"), 2.0);
  EXPECT_DOUBLE_EQ(p.Scalar("n"), 3.0);
  EXPECT_FALSE(p.FindScalar("a").has_value());
  EXPECT_FALSE(p.FindScalar("y0").has_value());
  EXPECT_EQ(p.Vector("a").size(), 2u);
  EXPECT_THAT([&] { p.Scalar("tau"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("no parameter 'tau' (parameters: K, a, n)")));
  EXPECT_THAT([&] { p.Vector("K"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("'K' is not a coefficient vector")));
}

}  // namespace
}  // namespace pneumid
