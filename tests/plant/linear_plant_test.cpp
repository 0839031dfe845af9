// Linear plants, the plant factory and the experiment runner.
#include "pneumid/plant/linear_plant.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/lti/response.hpp"
#include "pneumid/plant/experiment.hpp"
#include "pneumid/plant/ipa_simulator.hpp"
#include "pneumid/plant/mapped_plant.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;

Eigen::VectorXd Drive(Plant& plant, const Eigen::VectorXd& u) {
  Eigen::VectorXd y(u.size());
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    y[k] = plant.Measure();
    plant.Advance(u[k]);
  }
  return y;
}

TEST(LinearPlantTest, PaperArxModelEqualsLsim) {
  const TransferFunction g = PaperArxModel();
  LinearPlant plant(g, 0.01);
  const Eigen::VectorXd u =
      ParseSignal("prbs:low=0.61,high=82,order=7,clock=0.05")->Sample(0.01, 600);
  const Eigen::VectorXd y = Drive(plant, u);
  const Eigen::VectorXd ref = Lsim(g, u, 0.01);
  ASSERT_EQ(ref.size(), y.size());
  EXPECT_LT((y - ref).cwiseAbs().maxCoeff(), 1e-9 * ref.cwiseAbs().maxCoeff());
  // docs/paper.md, reference value 2: static gain 1.59796.
  Eigen::VectorXd step = Eigen::VectorXd::Ones(3000);
  plant.Reset();
  EXPECT_NEAR(Drive(plant, step)[2999], 1.59796, 1e-4);
}

TEST(LinearPlantTest, ContinuousFopdtIsSampledExactly) {
  // Zero-order-hold input constant from t = 0: the samples of the continuous
  // step response y(t) = K (1 - exp(-(t - theta)/tau)) for t > theta, with a
  // delay that is not a multiple of Ts.
  const double K = 1.6, tau = 0.245, theta = 0.015, Ts = 0.01;
  LinearPlant plant(TransferFunction::Fopdt(K, tau, theta), Ts);
  const Eigen::VectorXd y = Drive(plant, Eigen::VectorXd::Ones(200));
  for (int k = 0; k < 200; ++k) {
    const double t = k * Ts;
    const double expect = t > theta ? K * (1.0 - std::exp(-(t - theta) / tau)) : 0.0;
    EXPECT_NEAR(y[k], expect, 1e-9) << "k = " << k;
  }
  const Eigen::VectorXd u =
      ParseSignal("chirp:from=0,to=10,f0=0.1,f1=5,duration=2")->Sample(Ts, 250);
  plant.Reset();
  const Eigen::VectorXd yl = Drive(plant, u);
  const Eigen::VectorXd ref = Lsim(TransferFunction::Fopdt(K, tau, theta), u, Ts);
  EXPECT_LT((yl - ref).cwiseAbs().maxCoeff(), 1e-9);
}

// A direct feedthrough: (s + 1)/(s + 2) jumps with its input and decays to
// half of it. The sample y_k is taken before u_k is applied, so it is the
// model's output less the jump b0 (u_k - u_{k-1}) still to come; the
// recursion runs on the model's own output. It ran as 0.09 z^-1 / (1 - 0.82
// z^-1) (the feedthrough lost), rising slowly to 0.5.
TEST(LinearPlantTest, ADirectFeedthroughJumpsAfterTheSample) {
  const double Ts = 0.1;
  const TransferFunction g = TransferFunction::Continuous({1.0, 1.0}, {1.0, 2.0});
  LinearPlant plant(g, Ts);
  const Eigen::VectorXd u =
      ParseSignal("prbs:low=-1,high=2,order=5,clock=0.3")->Sample(Ts, 120);
  const Eigen::VectorXd y = Drive(plant, u);
  const Eigen::VectorXd model = Lsim(g, u, Ts);  // the output with u_k applied
  const double b0 = 1.0;                          // lim s->inf of G
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    const double before = k > 0 ? u[k - 1] : 0.0;
    EXPECT_NEAR(y[k], model[k] - b0 * (u[k] - before), 1e-9) << "k = " << k;
  }
  // A unit step at k = 0: 0 at the step's sample, then exp(-t) decaying from 1 to 0.5.
  plant.Reset();
  const Eigen::VectorXd s = Drive(plant, Eigen::VectorXd::Ones(30));
  EXPECT_EQ(s[0], 0.0);
  for (int k = 1; k < 30; ++k) EXPECT_NEAR(s[k], 0.5 + 0.5 * std::exp(-2.0 * k * Ts), 1e-9);
}

TEST(LinearPlantTest, NoiseIsSeededAndLoadDisturbanceAdds) {
  const TransferFunction g = PaperArxModel();
  LinearPlant a(g, 0.01, 0.5, 11), b(g, 0.01, 0.5, 11), c(g, 0.01, 0.5, 12);
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(4000, 10.0);
  const Eigen::VectorXd ya = Drive(a, u), yb = Drive(b, u), yc = Drive(c, u);
  EXPECT_EQ(ya, yb);
  EXPECT_NE(ya, yc);
  a.Reset();
  EXPECT_EQ(Drive(a, u), ya);
  // Noise statistics against the noise-free output.
  LinearPlant clean(g, 0.01);
  const Eigen::VectorXd e = ya - Drive(clean, u);
  const double mean = e.mean();
  const double sd = std::sqrt((e.array() - mean).square().sum() / (e.size() - 1));
  EXPECT_NEAR(sd, 0.5, 0.05);
  EXPECT_NEAR(mean, 0.0, 0.05);
  clean.Reset();
  clean.SetLoadDisturbance(-3.0);
  EXPECT_DOUBLE_EQ(clean.Measure(), -3.0);
}

TEST(LinearPlantTest, RejectsMismatchedSampleTime) {
  EXPECT_THROW(LinearPlant(PaperArxModel(), 0.02), InvalidArgument);
  EXPECT_THROW(LinearPlant(PaperArxModel(), 0.01, -1.0), InvalidArgument);
  EXPECT_THROW(LinearPlant(PaperArxModel(), 0.0), InvalidArgument);
}

TEST(PlantFactoryTest, MakesEveryKindOfPlant) {
  auto ipa = MakePlant("ipa", 0.01);
  ASSERT_NE(dynamic_cast<IpaSimulator*>(ipa.get()), nullptr);
  EXPECT_THAT(ipa->Describe(), HasSubstr("force mode"));
  EXPECT_EQ(PlantOutputChannel(*ipa).unit, "N");
  EXPECT_EQ(PlantInputChannel(*ipa).unit, "%");
  auto pos = MakePlant("ipa-position", 0.01);
  EXPECT_THAT(pos->Describe(), HasSubstr("position mode"));
  EXPECT_EQ(PlantOutputChannel(*pos).unit, "m");
  auto avg = MakePlant("ipa:pwm=averaged,mode=force", 0.01);
  EXPECT_THAT(avg->Describe(), HasSubstr("averaged"));
  PlantOptions options;
  options.config_path = std::string(PNEUMID_SOURCE_DIR) + "/config/ipa_default.toml";
  options.noise_sigma = 2.0;
  options.pwm_mode = PwmMode::kAveraged;
  auto configured = MakePlant("ipa", 0.01, options);
  const auto& p = dynamic_cast<IpaSimulator&>(*configured).parameters();
  EXPECT_NEAR(p.pressure_noise * p.AreaA(), 2.0, 1e-12);
  EXPECT_EQ(p.pwm_mode, PwmMode::kAveraged);

  auto arx = MakePlant("arx-paper", 0.01);
  EXPECT_NE(dynamic_cast<LinearPlant*>(arx.get()), nullptr);
  auto fopdt = MakePlant("fopdt:K=1.6,tau=0.245,theta=0.001", 0.01);
  for (int k = 0; k < 500; ++k) fopdt->Advance(1.0);
  EXPECT_NEAR(fopdt->Measure(), 1.6, 1e-6);
}

// A model file's plant is what the model predicts: G f(u) behind an input
// map, g(G u) with an output map (G: y_k = 0.5 y_{k-1} + 0.5 u_{k-1}, gain 1;
// maps through (0, 0), (50, 10), (100, 40)), each step response in closed
// form; a linear model runs in deviations from its operating point, as the
// controllers designed on it do.
TEST(PlantFactoryTest, AModelFilesPlantRunsItsMaps) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / "pneumid_mapped_plant_test.json";
  const std::string g = R"("tf": {"num": [0, 0.5], "den": [1, -0.5], "Ts": 0.1, "delay": 0})";
  const std::string map = R"({"u": [0, 50, 100], "y": [0, 10, 40]})";
  std::ofstream(file) << "{\"models\": [{\"method\": \"arx\", " << g
                      << R"(, "operating_point": {"u0": 2, "y0": 5}}, {"method": "hammerstein", )"
                      << g << ", \"input_map\": " << map << "}, {\"method\": \"wiener\", " << g
                      << ", \"output_map\": " << map << "}]}";
  const auto step = [](Plant& plant, double u, int k) {
    Eigen::VectorXd y(k + 1);
    for (int i = 0; i < k; ++i) {
      y[i] = plant.Measure();
      plant.Advance(u);
    }
    y[k] = plant.Measure();
    return y;
  };
  auto arx = MakePlant(file.string() + "#arx", 0.1);
  ASSERT_NE(dynamic_cast<LinearPlant*>(arx.get()), nullptr);
  Eigen::VectorXd y = step(*arx, 10.0, 3);  // 10 (1 - 0.5^k)
  EXPECT_NEAR(y[3], 10.0 * 0.875, 1e-12);
  auto hammerstein = MakePlant(file.string() + "#hammerstein", 0.1);
  ASSERT_NE(dynamic_cast<MappedPlant*>(hammerstein.get()), nullptr);
  EXPECT_THAT(hammerstein->Describe(), HasSubstr("behind its input map"));
  y = step(*hammerstein, 75.0, 40);  // f(75) = 25
  EXPECT_NEAR(y[1], 12.5, 1e-12);
  EXPECT_NEAR(y[40], 25.0, 1e-9);
  auto wiener = MakePlant(file.string() + "#wiener", 0.1);
  y = step(*wiener, 75.0, 40);  // g(37.5) = 7.5, g(75) = 25
  EXPECT_NEAR(y[1], 7.5, 1e-12);
  EXPECT_NEAR(y[40], 25.0, 1e-9);
  EXPECT_NEAR(wiener->Extras().at("x"), 75.0, 1e-9);
  EXPECT_THAT(wiener->Describe(), HasSubstr("with its output map"));
  std::filesystem::remove(file);
}

TEST(PlantFactoryTest, BadSpecsGiveClearErrors) {
  EXPECT_THROW(MakePlant("", 0.01), InvalidArgument);
  EXPECT_THROW(MakePlant("no-such-plant", 0.01), InvalidArgument);
  try {
    MakePlant("ipa:speed=3", 0.01);
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown key 'speed'"));
  }
  EXPECT_THROW(MakePlant("ipa:config=/nonexistent.toml", 0.01), DataError);
  EXPECT_THROW(MakePlant("ipa", -1.0), InvalidArgument);
  PlantOptions bad;
  bad.noise_sigma = -1.0;
  EXPECT_THROW(MakePlant("arx-paper", 0.01, bad), InvalidArgument);
}

TEST(ExperimentTest, RecordsInputOutputAndExtras) {
  auto plant = MakePlant("arx-paper", 0.01);
  auto input = ParseSignal("step:from=0.61,to=82,at=1.0");
  double last_progress = 0.0;
  ExperimentOptions options;
  options.progress = [&](double f) {
    EXPECT_GE(f, last_progress);
    last_progress = f;
  };
  const Experiment e = RunExperiment(*plant, *input, 4.0, options);
  ASSERT_EQ(e.data.size(), 401);
  EXPECT_DOUBLE_EQ(last_progress, 1.0);
  EXPECT_NEAR(e.data.time()[400], 4.0, 1e-12);
  EXPECT_DOUBLE_EQ(e.data.u()[99], 0.61);
  EXPECT_DOUBLE_EQ(e.data.u()[100], 82.0);
  const Eigen::VectorXd ref = Lsim(PaperArxModel(), e.data.u(), 0.01);
  EXPECT_LT((e.data.y() - ref).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_THROW(RunExperiment(*plant, *input, 0.001), InvalidArgument);
}

TEST(ExperimentTest, SavesCsvAndMatWithChamberPressures) {
  auto plant = MakePlant("ipa", 0.01);
  auto input = ParseSignal("step:from=0.61,to=82,at=0.5");
  ExperimentOptions options;
  options.input_channel = PlantInputChannel(*plant);
  options.output_channel = PlantOutputChannel(*plant);
  const Experiment e = RunExperiment(*plant, *input, 1.5, options);
  ASSERT_EQ(e.extras.size(), 2u);
  EXPECT_EQ(e.extras[0].channel.name, "p_a");
  EXPECT_EQ(e.extras[0].channel.unit, "Pa");
  EXPECT_GT(e.extras[0].values[150], 5e5);

  for (const std::string ext : {".csv", ".mat"}) {
    const std::string path = std::string(PNEUMID_BINARY_DIR) + "/experiment_test" + ext;
    SaveExperiment(e, path);
    const Dataset back = LoadDataset(path);
    ASSERT_EQ(back.size(), e.data.size()) << ext;
    EXPECT_LT((back.y() - e.data.y()).cwiseAbs().maxCoeff(), 1e-12) << ext;
    EXPECT_LT((back.u() - e.data.u()).cwiseAbs().maxCoeff(), 1e-12) << ext;
    LoadOptions pa;
    pa.output_columns = {"p_a"};
    const Dataset pressures = LoadDataset(path, pa);
    EXPECT_LT((pressures.y() - e.extras[0].values).cwiseAbs().maxCoeff(), 1e-9) << ext;
    std::remove(path.c_str());
  }
}

}  // namespace
}  // namespace pneumid
