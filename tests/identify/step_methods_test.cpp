// Every step-response method on recorded synthetic plants (FOPDT, SOPDT,
// third order; 1 % noise, tests/identify/gen_synthetic_steps.py, responses by
// scipy.signal.step), the accuracy of each against the true plant, and the
// table of errors in docs/identification.md, printed by
//   build/pneumid_identify_tests --gtest_filter='StepMethodComparison.*'
#include "pneumid/identify/step/step_methods.hpp"

#include <cmath>
#include <iostream>
#include <map>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/models/model_file.hpp"
#include "step_test_util.hpp"

namespace pneumid {
namespace {

struct Plant {
  std::string name;
  TransferFunction truth;
  double K, tau1, tau2, theta;  // tau2 = 0 for FOPDT; NaN when not comparable
  std::string reference;        // the fit that must beat every graphical method
};

std::vector<Plant> Plants() {
  const double nan = std::nan("");
  return {
      {"fopdt", TransferFunction::Fopdt(2.5, 1.5, 0.413), 2.5, 1.5, 0.0, 0.413, "fit-p1d"},
      {"sopdt", TransferFunction::Sopdt(1.2, 2.0, 0.7, 0.537), 1.2, 2.0, 0.7, 0.537, "fit-p2d"},
      {"high_order", TransferFunction::Continuous({0.8}, {0.125, 0.875, 1.75, 1.0}, 0.3), 0.8, nan,
       nan, nan, "fit-p2d"},
  };
}

// Fit (NRMSE %) of the model's response to the recorded input against the
// plant's noise-free response, both in deviation from the initial steady state.
double TrueResponseFit(const TransferFunction& g, const Dataset& noisy, const Dataset& truth) {
  const Eigen::VectorXd u = noisy.u(0);
  const Eigen::VectorXd yhat = Lsim(g, (u.array() - u[0]).matrix(), noisy.SampleTime());
  const Eigen::VectorXd y = truth.y(0).array() - truth.y(0)[0];
  return NrmseFit(y, yhat);
}

double Param(const IdentifiedModel& m, const char* name) {
  return m.params.FindScalar(name).value_or(std::nan(""));
}

struct Row {
  std::string method, structure;
  double k_err, tau1_err, tau2_err, theta_err_samples, true_fit, data_fit;
};

std::map<std::string, std::vector<Row>> RunAll() {
  std::map<std::string, std::vector<Row>> out;
  IdentifyRequest req;
  req.order = 2;
  for (const Plant& p : Plants()) {
    const Dataset noisy = testing::LoadSynthetic(p.name);
    const Dataset truth = testing::LoadSynthetic(p.name, true);
    const double Ts = noisy.SampleTime();
    for (const std::string& method : StepMethodNames()) {
      if (method == "fit-p1di") continue;  // integrating structure: not for these plants
      const IdentifiedModel m = IdentifyStepMethod(method, noisy, req);
      Row r;
      r.method = method;
      r.structure = m.structure;
      r.k_err = 100.0 * (Param(m, "K") - p.K) / p.K;
      double t1 = Param(m, "tau"), t2 = 0.0;
      if (std::isnan(t1)) {
        t1 = Param(m, "tau1");
        t2 = Param(m, "tau2");
      }
      const bool first_order = m.structure == "FOPDT" || m.structure == "P1D";
      const bool second_order = m.structure == "SOPDT" || m.structure == "P2D";
      const bool comparable = (p.tau2 == 0.0 && first_order) || (p.tau2 > 0.0 && second_order);
      r.tau1_err = comparable ? 100.0 * (t1 - p.tau1) / p.tau1 : std::nan("");
      r.tau2_err = comparable && p.tau2 > 0.0 ? 100.0 * (t2 - p.tau2) / p.tau2 : std::nan("");
      r.theta_err_samples = comparable ? (Param(m, "theta") - p.theta) / Ts : std::nan("");
      r.true_fit = TrueResponseFit(m.tf, noisy, truth);
      r.data_fit = m.fit_percent;
      out[p.name].push_back(r);
    }
  }
  return out;
}

const std::map<std::string, std::vector<Row>>& Results() {
  static const auto results = RunAll();
  return results;
}

const Row& Find(const std::string& plant, const std::string& method) {
  for (const Row& r : Results().at(plant)) {
    if (r.method == method) return r;
  }
  throw std::runtime_error("no row " + method);
}

TEST(StepMethodComparison, FittedFopdtRecoversTruePlant) {
  const Row& r = Find("fopdt", "fit-p1d");
  EXPECT_LT(std::abs(r.k_err), 2.0);
  EXPECT_LT(std::abs(r.tau1_err), 2.0);
  EXPECT_LT(std::abs(r.theta_err_samples), 1.0);
}

TEST(StepMethodComparison, FittedSopdtRecoversTruePlant) {
  const Row& r = Find("sopdt", "fit-p2d");
  EXPECT_LT(std::abs(r.k_err), 2.0);
  EXPECT_LT(std::abs(r.tau1_err), 2.0);
  EXPECT_LT(std::abs(r.theta_err_samples), 1.0);
  // One step with 1 % noise pins tau2 down to 3.4 % (one standard deviation,
  // Cramer-Rao bound printed by gen_synthetic_steps.py), not to 2 %: here the
  // error must lie within three of the fit's own standard deviations, and the
  // 2 % recovery is shown on ten steps in process_model_test.cpp.
  const IdentifiedModel m = IdentifyStepMethod("fit-p2d", testing::LoadSynthetic("sopdt"), {});
  const double sd = m.param_std.Scalar("tau2");
  EXPECT_NEAR(sd / 0.7, 0.034, 0.01);
  EXPECT_LT(std::abs(r.tau2_err / 100.0 * 0.7), 3.0 * sd);
}

TEST(StepMethodComparison, FitsBeatEveryGraphicalMethod) {
  for (const Plant& p : Plants()) {
    const Row& ref = Find(p.name, p.reference);
    for (const Row& r : Results().at(p.name)) {
      if (r.method.rfind("fit-", 0) == 0) continue;
      EXPECT_GT(ref.true_fit, r.true_fit) << p.name << ": " << p.reference << " vs " << r.method;
      EXPECT_GT(ref.data_fit, r.data_fit) << p.name << ": " << p.reference << " vs " << r.method;
    }
  }
  // On the FOPDT plant the fitted parameters are also closer than every
  // graphical FOPDT's (largest of the relative gain, time-constant and delay errors).
  const Row& ref = Find("fopdt", "fit-p1d");
  auto worst = [](const Row& r) {
    return std::max({std::abs(r.k_err), std::abs(r.tau1_err),
                     std::abs(r.theta_err_samples * 0.02 / 0.413 * 100.0)});
  };
  for (const Row& r : Results().at("fopdt")) {
    if (r.structure == "FOPDT") EXPECT_LT(worst(ref), worst(r)) << r.method;
  }
}

TEST(StepMethodComparison, PrintTable) {
  auto cell = [](double v, const char* f) {
    return std::isnan(v) ? std::string("-") : fmt::format(fmt::runtime(f), v);
  };
  for (const Plant& p : Plants()) {
    std::cout << fmt::format("\n#### {} plant: {}\n\n", p.name, p.truth.ToString(4));
    std::cout << "| method | structure | K err % | tau(1) err % | tau2 err % | theta err "
                 "[samples] | fit to true response % | fit to data % |\n";
    std::cout << "|---|---|---|---|---|---|---|---|\n";
    for (const Row& r : Results().at(p.name)) {
      std::cout << fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |\n", r.method, r.structure,
                               cell(r.k_err, "{:+.2f}"), cell(r.tau1_err, "{:+.2f}"),
                               cell(r.tau2_err, "{:+.2f}"), cell(r.theta_err_samples, "{:+.2f}"),
                               cell(r.true_fit, "{:.2f}"), cell(r.data_fit, "{:.2f}"));
      // Every method gives a model whose response follows the data: a
      // method that fails or returns a wrong-signed or empty model shows here.
      EXPECT_TRUE(std::isfinite(r.k_err)) << p.name << " " << r.method;
      EXPECT_GT(r.true_fit, 50.0) << p.name << " " << r.method;
      EXPECT_GT(r.data_fit, 50.0) << p.name << " " << r.method;
    }
    EXPECT_GE(Results().at(p.name).size(), 6u) << p.name;
  }
}

TEST(StepMethodsTest, NamesAndErrors) {
  EXPECT_TRUE(IsStepMethod("reaction-curve"));
  EXPECT_TRUE(IsStepMethod("fit-p1di"));
  EXPECT_FALSE(IsStepMethod("arx"));
  const Dataset d = testing::LoadSynthetic("fopdt");
  EXPECT_THAT([&] { IdentifyStepMethod("bogus", d, {}); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("bogus")));
  IdentifyRequest bad;
  bad.order = 0;
  EXPECT_THROW(IdentifyStepMethod("ptn", d, bad), InvalidArgument);
}

TEST(StepMethodsTest, JsonForm) {
  const Dataset d = testing::LoadSynthetic("fopdt");
  const IdentifiedModel m = IdentifyStepMethod("reaction-curve", d, {});
  const nlohmann::json j = ToJson(m);
  EXPECT_EQ(j["method"], "reaction-curve");
  EXPECT_EQ(j["structure"], "FOPDT");
  for (const char* key : {"K", "tau", "theta"}) EXPECT_TRUE(j["params"].contains(key)) << key;
  EXPECT_EQ(j["tf"]["Ts"], 0.0);
  EXPECT_NEAR(j["tf"]["delay"].get<double>(), m.params.Scalar("theta"), 1e-12);
  EXPECT_GT(j["fit_percent"].get<double>(), 90.0);
  const TransferFunction back = TransferFunctionFromJson(j["tf"]);
  EXPECT_NEAR(back.DcGain(), m.params.Scalar("K"), 1e-9);
}

}  // namespace
}  // namespace pneumid
