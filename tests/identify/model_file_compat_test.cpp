// Model files written by earlier versions of pneumid keep loading.
//
// tests/data/model_files/<version>/ holds files that the program of that
// version wrote (`pneumid identify DATA -o FILE.json`, by generate.sh in
// tests/data/model_files/; never edited by hand), next to the data they were
// identified from: FILE is "<data>.<group>.json", identified from
// "<data>.csv" of the same folder. For every model entry of every file:
//   * LoadIdentifiedModel reads it, with its method;
//   * ParseModelSpec gives its transfer function (a NARX model has none: the
//     error says so), ParseModelInputMap / ParseModelOutputMap /
//     ParseModelNarx a map or a NARX exactly when the entry has one;
//   * written back with ToJson it reads again to the same model, and the keys
//     the old file had are written with the same values;
//   * simulated now on its data it gives the fit the file states (1e-6
//     relative): a model file means the same model in this version. One
//     convention changed since: a Wiener or Hammerstein-Wiener model whose
//     output map turns now starts at rest at the first measured output (the
//     preimage nearest the rest at the first input, SimulateNonlinear), as a
//     monotone one always did; it started at rest at the first input before.
//     Such an entry is simulated from that old start (SimulateNonlinear
//     without an output column) for the comparison.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pneumid/data/load.hpp"
#include "pneumid/data/preprocess.hpp"
#include "pneumid/data/preprocess_io.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/nonlinear/nonlinear.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/models/narx_model.hpp"
#include "pneumid/models/static_map.hpp"

namespace pneumid {
namespace {

namespace fs = std::filesystem;

fs::path FixtureRoot() { return fs::path(PNEUMID_SOURCE_DIR) / "tests" / "data" / "model_files"; }

// One model entry of one fixture file.
struct Entry {
  std::string file;    // path of the model file
  std::string data;    // path of the CSV it was identified from
  std::string method;  // the entry's "method"
  std::string name;    // test name: <version>_<file stem>_<method>, [A-Za-z0-9_] only
};

// Failure messages name the entry, not the bytes of the struct.
void PrintTo(const Entry& e, std::ostream* os) { *os << e.file << "#" << e.method; }

std::string TestName(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// The model files of every version folder, sorted.
std::vector<fs::path> ModelFiles() {
  std::vector<fs::path> files;
  std::error_code ec;
  if (!fs::is_directory(FixtureRoot(), ec)) return files;
  for (const fs::directory_entry& dir : fs::directory_iterator(FixtureRoot())) {
    if (!dir.is_directory()) continue;
    for (const fs::directory_entry& f : fs::directory_iterator(dir.path()))
      if (f.is_regular_file() && f.path().extension() == ".json") files.push_back(f.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Every model entry; a file that cannot be read is left out here and fails
// ModelFileCompat.EveryFileHoldsModels.
std::vector<Entry> Entries() {
  std::vector<Entry> entries;
  for (const fs::path& file : ModelFiles()) {
    try {
      const nlohmann::json j = ReadJson(file.string());
      const std::string stem = file.stem().string();
      const fs::path data = file.parent_path() / (stem.substr(0, stem.find('.')) + ".csv");
      for (const nlohmann::json& m : j.at("models")) {
        const std::string method = m.at("method").get<std::string>();
        entries.push_back(
            {file.string(), data.string(), method,
             TestName(file.parent_path().filename().string() + "_" + stem + "_" + method)});
      }
    } catch (const std::exception&) {
    }
  }
  return entries;
}

std::vector<double> Coefficients(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

void ExpectSameTf(const TransferFunction& a, const TransferFunction& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(Coefficients(a.num()), Coefficients(b.num()));
  EXPECT_EQ(Coefficients(a.den()), Coefficients(b.den()));
  EXPECT_EQ(a.Ts(), b.Ts());
  EXPECT_EQ(a.delay(), b.delay());
}

// The fixtures exist and every file is a model file with models and data.
TEST(ModelFileCompat, EveryFileHoldsModels) {
  const std::vector<fs::path> files = ModelFiles();
  ASSERT_FALSE(files.empty()) << "no model files under " << FixtureRoot();
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.string());
    nlohmann::json j;
    ASSERT_NO_THROW(j = ReadJson(file.string()));
    ASSERT_TRUE(j.contains("models"));
    EXPECT_FALSE(j.at("models").empty());
    const std::string stem = file.stem().string();
    EXPECT_TRUE(fs::exists(file.parent_path() / (stem.substr(0, stem.find('.')) + ".csv")));
  }
}

class ModelFileCompatEntry : public ::testing::TestWithParam<Entry> {};

TEST_P(ModelFileCompatEntry, LoadsRoundTripsAndFitsAsWritten) {
  const Entry& e = GetParam();
  const std::string spec = e.file + "#" + e.method;
  SCOPED_TRACE(spec);
  const nlohmann::json file = ReadJson(e.file);
  nlohmann::json entry;
  for (const nlohmann::json& m : file.at("models"))
    if (m.at("method") == e.method) entry = m;
  ASSERT_TRUE(entry.is_object());

  // The identify area's reader.
  std::optional<IdentifiedModel> loaded;
  ASSERT_NO_THROW(loaded = LoadIdentifiedModel(spec));
  ASSERT_TRUE(loaded.has_value());
  const IdentifiedModel& m = *loaded;
  EXPECT_EQ(m.method, e.method);

  // lti's readers, as step/bode/control/simulate --model read the file.
  if (entry.contains("narx")) {
    EXPECT_THAT([&] { ParseModelSpec(spec); },
                ::testing::Throws<std::exception>(::testing::Property(
                    &std::exception::what, ::testing::HasSubstr("NARX model"))));
  } else {
    TransferFunction g;
    ASSERT_NO_THROW(g = ParseModelSpec(spec));
    const bool tustin = m.continuous_form == ContinuousForm::kTustin;
    ExpectSameTf(g, tustin ? *m.discrete : m.tf, "ParseModelSpec");
  }
  std::optional<StaticMap> input_map, output_map;
  std::optional<NarxWithMap> narx;
  ASSERT_NO_THROW(input_map = ParseModelInputMap(spec));
  ASSERT_NO_THROW(output_map = ParseModelOutputMap(spec));
  ASSERT_NO_THROW(narx = ParseModelNarx(spec));
  // A NARX model's input map feeds the NARX: ParseModelNarx gives it, not
  // ParseModelInputMap (model_io.hpp).
  EXPECT_EQ(input_map.has_value(), entry.contains("input_map") && !entry.contains("narx"));
  EXPECT_EQ(output_map.has_value(), entry.contains("output_map"));
  EXPECT_EQ(narx.has_value(), entry.contains("narx"));
  EXPECT_EQ(m.input_map.has_value(), entry.contains("input_map"));
  EXPECT_EQ(m.output_map.has_value(), entry.contains("output_map"));
  EXPECT_EQ(m.narx.has_value(), entry.contains("narx"));
  if (input_map) EXPECT_EQ(*input_map, *m.input_map);
  if (output_map) EXPECT_EQ(*output_map, *m.output_map);
  if (narx) {
    EXPECT_EQ(narx->narx, *m.narx);
    EXPECT_EQ(narx->input_map.has_value(), entry.contains("input_map"));
    if (narx->input_map) EXPECT_EQ(*narx->input_map, *m.input_map);
  }

  // Written back and read again: the same model.
  const nlohmann::json written = ToJson(m);
  const IdentifiedModel back = IdentifiedModelFromJson(written);
  EXPECT_EQ(back.method, m.method);
  EXPECT_EQ(back.structure, m.structure);
  EXPECT_EQ(back.params, m.params);
  EXPECT_EQ(back.param_std, m.param_std);
  ExpectSameTf(back.tf, m.tf, "tf");
  ASSERT_EQ(back.discrete.has_value(), m.discrete.has_value());
  if (m.discrete) ExpectSameTf(*back.discrete, *m.discrete, "discrete");
  EXPECT_EQ(back.continuous_form, m.continuous_form);
  EXPECT_EQ(back.u0, m.u0);
  EXPECT_EQ(back.y0, m.y0);
  EXPECT_EQ(back.input_map, m.input_map);
  EXPECT_EQ(back.output_map, m.output_map);
  EXPECT_EQ(back.narx, m.narx);
  EXPECT_EQ(back.notes, m.notes);
  EXPECT_EQ(back.flags, m.flags);
  EXPECT_EQ(ToJson(back), written);
  // The keys of the old file are written back as they were (the file may
  // lack keys added since, e.g. continuous_form; rank_reason belongs to the
  // list written by identify, not to the model).
  for (const auto& [key, value] : entry.items()) {
    if (key == "rank_reason") continue;
    EXPECT_TRUE(written.contains(key)) << "key '" << key << "' is not written back";
    if (written.contains(key)) EXPECT_EQ(written.at(key), value) << "key '" << key << "'";
  }

  // Simulated now on the data it was identified from: the fit in the file.
  Dataset data = LoadDataset(e.data);
  if (m.preprocessing && !m.preprocessing->IsIdentity())
    data = ApplyRecorded(data, *m.preprocessing);
  FitMetrics f = EvaluateModel(m, data, 0, 0);
  if (m.output_map && !m.output_map->IsMonotone())
    f = ScoreSimulation(data, 0, SimulateNonlinear(m, data, 0, -1));
  ASSERT_TRUE(entry.at("fit_percent").is_number()) << entry.at("fit_percent");
  const double fit = entry.at("fit_percent").get<double>();
  EXPECT_NEAR(f.fit_percent, fit, 1e-6 * std::abs(fit));
  const double iae = entry.at("iae").get<double>();
  EXPECT_NEAR(f.iae, iae, 1e-6 * std::abs(iae));
}

INSTANTIATE_TEST_SUITE_P(ModelFileCompat, ModelFileCompatEntry, ::testing::ValuesIn(Entries()),
                         [](const ::testing::TestParamInfo<Entry>& info) {
                           return info.param.name;
                         });

}  // namespace
}  // namespace pneumid
