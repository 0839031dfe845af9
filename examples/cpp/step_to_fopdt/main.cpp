// From a logged step test to a tuned DMC loop with the pneumid C++ library:
//
//   1. read the step test (CSV with columns t, u, y),
//   2. identify a first-order-plus-dead-time model by the reaction curve,
//   3. tune a DMC controller from it (Shridhar-Cooper horizons),
//   4. close the loop around the IPA physics simulator and measure it.
//
// Usage: step_to_fopdt STEP.csv     (e.g. data/ipa_step.csv of the repository)
// Exit status 0 when the model and the loop meet the checks at the end.
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>

#include <pneumid/common/version.hpp>
#include <pneumid/control/closed_loop.hpp>
#include <pneumid/control/controller_factory.hpp>
#include <pneumid/data/load.hpp>
#include <pneumid/identify/identify.hpp>
#include <pneumid/plant/plant_factory.hpp>
#include <pneumid/plant/signal.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s STEP.csv\n", argv[0]);
    return 2;
  }
  try {
    // 1. The data: LoadDataset checks the file (numbers, increasing time)
    //    and throws pneumid::DataError naming file and line otherwise.
    const pneumid::Dataset data = pneumid::LoadDataset(argv[1]);
    const double Ts = data.MedianSampleInterval();
    std::printf("pneumid %s: %s, %ld samples, Ts = %g s\n", pneumid::Version(), argv[1],
                static_cast<long>(data.size()), Ts);

    // 2. FOPDT  K exp(-theta s) / (tau s + 1)  by the reaction curve.
    const pneumid::IdentifiedModel fopdt = pneumid::Identify("reaction-curve", data);
    const double K = fopdt.params.Scalar("K");
    const double tau = fopdt.params.Scalar("tau");
    const double theta = fopdt.params.Scalar("theta");
    std::printf("FOPDT: K = %.4f, tau = %.4f s, theta = %.4f s, fit %.2f %%\n", K, tau, theta,
                fopdt.fit_percent);

    // 3. DMC from the model; the rule's defaults (Shridhar-Cooper, M = 5),
    //    the input limited to the actuator's 0..100 % duty.
    pneumid::ControllerSpec spec;
    spec.type = pneumid::ControllerType::kDmc;
    spec.limits.u_min = 0.0;
    spec.limits.u_max = 100.0;
    pneumid::BuiltController dmc = pneumid::MakeController(fopdt.tf, Ts, spec);
    std::printf("DMC: P = %d, M = %d, lambda = %.4g\n", dmc.tuning.P, dmc.tuning.M,
                dmc.tuning.lambda);

    // 4. The loop around the nonlinear IPA simulator (not the model):
    //    set-point 0 -> 40 -> 80 -> 40 N, 2 s each, a -15 N load at 7 s.
    std::unique_ptr<pneumid::Plant> ipa = pneumid::MakePlant("ipa", Ts);
    std::unique_ptr<pneumid::Signal> setpoint =
        pneumid::ParseSignal("staircase:levels=0 40 80 40,dwell=2");
    pneumid::ClosedLoopOptions options;
    options.duration = 8.0;
    options.load_steps = {{7.0, -15.0}};
    const pneumid::ClosedLoopResult run =
        pneumid::SimulateClosedLoop(*dmc.controller, *ipa, *setpoint, options);
    const pneumid::ClosedLoopMetrics& m = run.metrics;
    std::printf("closed loop: rise %.3f s, overshoot %.2f %%, settling %.3f s, IAE %.2f N s\n",
                m.rise_time, m.overshoot_percent, m.settling_time, m.iae);
    std::printf("             load peak %.2f N, recovered in %.2f s, duty %.1f..%.1f %%\n",
                m.load_peak_deviation, m.load_recovery_time, m.u_min, m.u_max);

    // Checks (margins around today's values: K 1.599, fit 99.2 %, IAE 13.7).
    bool ok = true;
    auto check = [&ok](bool condition, const char* what) {
      if (!condition) {
        std::fprintf(stderr, "check failed: %s\n", what);
        ok = false;
      }
    };
    check(std::abs(K - 1.6) < 0.1, "static gain K within 0.1 of 1.6 N/%");
    check(fopdt.fit_percent > 95.0, "model fit above 95 %");
    check(m.settled, "the first set-point step settles");
    check(m.iae < 20.0, "IAE below 20 N s");
    check(m.u_min >= 0.0 && m.u_max <= 100.0, "duty within 0..100 %");
    check(std::abs(run.y(run.y.size() - 1) - 40.0) < 1.0, "back at 40 N after the load");
    std::printf("%s\n", ok ? "all checks passed" : "FAILED");
    return ok ? 0 : 1;
  } catch (const std::exception& e) {  // pneumid::DataError, pneumid::InvalidArgument
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
