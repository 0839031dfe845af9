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
#include "pneumid/models/model_file.hpp"
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
  expected["continuous_form"] = "zoh";  // a discrete model without a tustin note
  EXPECT_EQ(ToJson(m), expected);
  EXPECT_EQ(ToJson(m)["params"]["nk"].dump(), "1");
}

// How the continuous form derives from the discrete one is a typed field
// ("continuous_form"); files written before it existed said so in a note.
TEST(IdentifiedModelIoTest, TheContinuousFormIsATypedFieldAndOlderNotesStillSayIt) {
  nlohmann::json j = nlohmann::json::parse(kWritten);
  j["notes"] = {"continuous form by tustin d2c: no zoh equivalent (pole at z = -0.3)"};
  EXPECT_EQ(IdentifiedModelFromJson(j).continuous_form, ContinuousForm::kTustin);
  j["notes"] = {"no continuous (zoh d2c) equivalent: pole at z = -1; tustin: pole at z = -1"};
  EXPECT_EQ(IdentifiedModelFromJson(j).continuous_form, ContinuousForm::kNone);
  // The key wins over any note, and it round-trips.
  j["continuous_form"] = "tustin";
  j["notes"] = {"a note"};
  const IdentifiedModel m = IdentifiedModelFromJson(j);
  EXPECT_EQ(m.continuous_form, ContinuousForm::kTustin);
  EXPECT_EQ(ToJson(m)["continuous_form"], "tustin");
  // Models without a discrete form have none.
  j.erase("discrete");
  j.erase("continuous_form");
  EXPECT_FALSE(IdentifiedModelFromJson(j).continuous_form.has_value());
  j["continuous_form"] = "bilinear";
  EXPECT_THAT([&] { IdentifiedModelFromJson(j); },
              ThrowsMessage<InvalidArgument>(HasSubstr("zoh, tustin, none")));
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
  for (const char* key : {"a", "b", "nk", "Ts"})
    EXPECT_TRUE(j["models"][0]["params"].contains(key));
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
  EXPECT_THAT(
      [] {
        ModelParamsFromJson(nlohmann::json{{"K", "big"}});
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("parameter 'K'")));
  EXPECT_THAT(
      [] {
        ModelParamsFromJson(nlohmann::json{{"a", {1.0, "x"}}});
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("parameter 'a'")));
  nlohmann::json no_tf = nlohmann::json::parse(kWritten);
  no_tf.erase("tf");
  EXPECT_THAT([&] { IdentifiedModelFromJson(no_tf); },
              ThrowsMessage<InvalidArgument>(HasSubstr("'tf'")));
}

// Identified models are read through lti's one model-file reader: the same
// #method selection, plain transfer functions and inline specs left to
// ParseModelSpec, errors that name the file.
TEST(IdentifiedModelIoTest, LoadIdentifiedModelSelectsAsEveryReaderDoes) {
  const auto dir = std::filesystem::temp_directory_path() / "pneumid_load_identified";
  std::filesystem::create_directories(dir);
  nlohmann::json second = nlohmann::json::parse(kWritten);
  second["method"] = "arx";
  second["params"] = {{"K", 2.5}};
  const std::string file = (dir / "models.json").string();
  std::ofstream(file) << nlohmann::json{{"models", {nlohmann::json::parse(kWritten), second}}};
  ASSERT_TRUE(LoadIdentifiedModel(file).has_value());
  EXPECT_EQ(LoadIdentifiedModel(file)->method, "n4sid");  // the first without #method
  EXPECT_DOUBLE_EQ(LoadIdentifiedModel(file + "#arx")->params.Scalar("K"), 2.5);
  EXPECT_THAT(
      [&] { LoadIdentifiedModel(file + "#oe"); },
      ThrowsMessage<DataError>(HasSubstr("no model with method 'oe' (available: n4sid, arx)")));
  const std::string plain = (dir / "tf.json").string();
  std::ofstream(plain) << R"({"num": [1], "den": [1, 1], "Ts": 0, "delay": 0})";
  EXPECT_FALSE(LoadIdentifiedModel(plain).has_value());
  EXPECT_FALSE(LoadIdentifiedModel("fopdt:K=1,tau=1,theta=0").has_value());
  EXPECT_THAT([&] { LoadIdentifiedModel((dir / "missing.json").string()); },
              ThrowsMessage<DataError>(HasSubstr("missing.json: cannot open model file")));
  const std::string broken = (dir / "broken.json").string();
  std::ofstream(broken) << "{\"models\": [";
  EXPECT_THAT([&] { LoadIdentifiedModel(broken); },
              ThrowsMessage<DataError>(HasSubstr("broken.json:1:")));
  std::filesystem::remove_all(dir);
}

TEST(IdentifiedModelIoTest, SaveModelFileWritesWhatLoadIdentifiedModelReads) {
  const auto dir = std::filesystem::temp_directory_path() / "pneumid_save_model_file";
  std::filesystem::create_directories(dir);
  IdentifiedModel first = IdentifiedModelFromJson(nlohmann::json::parse(kWritten));
  IdentifiedModel second = first;
  second.method = "arx";
  second.params = ModelParamsFromJson({{"K", 2.5}});
  nlohmann::json doc = ModelFileDocument({first, second});
  ASSERT_EQ(doc.at("models").size(), 2u);
  EXPECT_EQ(doc.at("models")[0], ToJson(first));
  doc["best"] = "n4sid";
  const std::string file = (dir / "models.json").string();
  SaveModelFile(file, doc);
  EXPECT_EQ(LoadIdentifiedModel(file)->method, "n4sid");
  EXPECT_DOUBLE_EQ(LoadIdentifiedModel(file + "#arx")->params.Scalar("K"), 2.5);
  EXPECT_EQ(ParseModelSpec(file + "#arx").ToString(6), second.tf.ToString(6));
  std::ifstream in(file);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, doc.dump(2) + "\n");
  const std::string nowhere = (dir / "no" / "such" / "dir.json").string();
  EXPECT_THAT([&] { SaveModelFile(nowhere, doc); },
              ThrowsMessage<DataError>(HasSubstr("dir.json: cannot open for writing")));
  std::filesystem::remove_all(dir);
}

TEST(ModelParamsTest, TypedAccessors) {
  ModelParams p{{"K", 2.0}, {"n", 3}, {"a", std::vector<double>{1.0, 0.5}}};
  EXPECT_DOUBLE_EQ(p.Scalar("K"), 2.0);
  EXPECT_DOUBLE_EQ(p.Scalar("n"), 3.0);
  EXPECT_FALSE(p.FindScalar("a").has_value());
  EXPECT_FALSE(p.FindScalar("y0").has_value());
  EXPECT_EQ(p.Vector("a").size(), 2u);
  EXPECT_THAT([&] { p.Scalar("tau"); }, ThrowsMessage<InvalidArgument>(
                                            HasSubstr("no parameter 'tau' (parameters: K, a, n)")));
  EXPECT_THAT([&] { p.Vector("K"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("'K' is not a coefficient vector")));
}

}  // namespace
}  // namespace pneumid
