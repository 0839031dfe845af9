// Frequency response and stability margins against closed forms and scipy
// (values from gen_frequency_cases.py).
#include "pneumid/lti/frequency.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(FrequencyTest, LogSpace) {
  const Eigen::VectorXd w = LogSpace(-1, 2, 4);
  ASSERT_EQ(w.size(), 4);
  EXPECT_NEAR(w[0], 0.1, 1e-15);
  EXPECT_NEAR(w[1], 1.0, 1e-15);
  EXPECT_NEAR(w[3], 100.0, 1e-12);
  EXPECT_THAT([] { LogSpace(1, 0, 3); }, ThrowsMessage<InvalidArgument>(HasSubstr("lo <= hi")));
  EXPECT_THAT([] { LogSpace(0, 1, 0); }, ThrowsMessage<InvalidArgument>(HasSubstr("n >= 1")));
}

TEST(FrequencyTest, BodeContinuousMatchesScipy) {
  // scipy.signal.freqresp(([1, 2], [1, 0.4, 4]), w)
  Eigen::VectorXd w(5);
  w << 0.1, 1.0, 2.0, 5.0, 30.0;
  const double mag[] = {0.50185409012636, 0.738817655706927, 3.53553390593274, 0.255281294508318,
                        0.0335534560466297};
  const double phase[] = {2.28803068792352, 18.9704078084865, -45, -106.361077455346,
                          -93.0467665192007};
  const BodeData b = Bode(TransferFunction::Continuous({1, 2}, {1, 0.4, 4}), w);
  for (int i = 0; i < 5; ++i) {
    EXPECT_NEAR(b.magnitude[i] / mag[i], 1.0, 1e-12) << i;
    EXPECT_NEAR(b.magnitude_db[i], 20 * std::log10(mag[i]), 1e-10) << i;
    EXPECT_NEAR(b.phase_deg[i], phase[i], 1e-9) << i;
  }
}

TEST(FrequencyTest, BodeDiscreteMatchesScipyAndUnwraps) {
  // scipy.signal.dfreqresp of the paper's ARX model at w Ts.
  Eigen::VectorXd w(4);
  w << 0.5, 5.0, 50.0, 300.0;
  const double mag[] = {1.58779416936795, 1.05705885753605, 0.139153022998534, 0.00546100190036911};
  const double phase[] = {-6.72346499310409, -51.145821492697, -110.752939827913,
                          -194.561129568104};
  const BodeData b = Bode(PaperArxModel(), w);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(b.magnitude[i] / mag[i], 1.0, 1e-10) << i;
    EXPECT_NEAR(b.phase_deg[i], phase[i], 1e-8) << i;
  }
  EXPECT_THAT([] { Bode(PaperArxModel(), Eigen::VectorXd::Constant(1, 400.0)); },
              ThrowsMessage<InvalidArgument>(HasSubstr("exceeds the Nyquist frequency")));
}

TEST(FrequencyTest, BodeDelayPhaseIsUnwrapped) {
  // exp(-s) / (s + 1): phase = -atan(w) - w, monotonically decreasing past -180 deg.
  const TransferFunction g = TransferFunction::Continuous({1}, {1, 1}, 1.0);
  const BodeData b = Bode(g, LogSpace(-2, 2, 400));
  for (Eigen::Index i = 0; i < b.omega.size(); ++i) {
    const double w = b.omega[i];
    ASSERT_NEAR(b.phase_deg[i], (-std::atan(w) - w) * 180 / M_PI, 1e-9);
  }
  // Five points four decades apart (bode --points 5): the delay turns the
  // phase by thousands of degrees between them, and it is still the closed form.
  Eigen::VectorXd coarse(5);
  coarse << 0.1, 10.0, 100.0, 1000.0, 10000.0;
  const TransferFunction fopdt = TransferFunction::Continuous({1.6}, {0.2, 1}, 0.05);
  const BodeData c = Bode(fopdt, coarse);
  for (int k = 0; k < 5; ++k) {
    const double w = coarse[k];
    EXPECT_NEAR(c.phase_deg[k], (-std::atan(0.2 * w) - 0.05 * w) * 180 / M_PI, 1e-9) << w;
  }
  // A discrete model on a coarse grid has the phase of the fine grid at the
  // same frequencies (its poles' factors cross the branch cut in between).
  Eigen::VectorXd few(3);
  few << 1.0, 100.0, 314.0;
  const BodeData d_few = Bode(PaperArxModel(), few);
  const BodeData d_fine = Bode(PaperArxModel(), LogSpace(0.0, std::log10(314.0), 2001));
  EXPECT_NEAR(d_few.phase_deg[0], d_fine.phase_deg[0], 1e-9);
  EXPECT_NEAR(d_few.phase_deg[2], d_fine.phase_deg[2000], 1e-9);
  // Automatic grid spans the corner frequency.
  const BodeData a = Bode(g);
  EXPECT_LT(a.omega[0], 1.0);
  EXPECT_GT(a.omega[a.omega.size() - 1], 1.0);
  // Integrator: -90 deg at every frequency.
  const BodeData i = Bode(TransferFunction::Continuous({1}, {1, 0}), LogSpace(-1, 1, 5));
  EXPECT_NEAR(i.phase_deg[2], -90.0, 1e-12);
  EXPECT_NEAR(i.magnitude[2], 1.0, 1e-12);
}

TEST(FrequencyTest, MarginsOfTypeOneSystem) {
  // 1 / (s (s + 1) (s + 2)): phase crossover sqrt(2) rad/s, GM = 6; gain
  // crossover 0.445747959631896 rad/s, PM = 53.4107861776991 deg.
  const Margins m = ComputeMargins(TransferFunction::Continuous({1}, {1, 3, 2, 0}));
  EXPECT_NEAR(m.phase_crossover, std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(m.gain_margin, 6.0, 1e-9);
  EXPECT_NEAR(m.gain_margin_db, 20 * std::log10(6.0), 1e-8);
  EXPECT_NEAR(m.gain_crossover, 0.445747959631896, 1e-9);
  EXPECT_NEAR(m.phase_margin, 53.4107861776991, 1e-7);
}

TEST(FrequencyTest, MarginsOfPaperFopdt) {
  // 1.6 exp(-0.001 s) / (0.245 s + 1): gain crossover sqrt(1.6^2 - 1)/0.245.
  const Margins m = ComputeMargins(PaperFopdtModel());
  EXPECT_NEAR(m.gain_crossover, std::sqrt(1.6 * 1.6 - 1) / 0.245, 1e-9);
  EXPECT_NEAR(m.phase_margin, 128.390096001754, 1e-7);
  EXPECT_NEAR(m.phase_crossover, 1573.39048478462, 1e-6);
  EXPECT_NEAR(m.gain_margin, 240.926228657472, 1e-6);
}

TEST(FrequencyTest, NoCrossingsGiveInfinity) {
  // 0.5 / (s + 1): |G| < 1 and phase > -90 everywhere.
  const Margins m = ComputeMargins(TransferFunction::Continuous({0.5}, {1, 1}));
  EXPECT_TRUE(std::isinf(m.gain_margin));
  EXPECT_TRUE(std::isinf(m.phase_margin));
  EXPECT_TRUE(std::isnan(m.gain_crossover));
  EXPECT_TRUE(std::isnan(m.phase_crossover));
}

}  // namespace
}  // namespace pneumid
