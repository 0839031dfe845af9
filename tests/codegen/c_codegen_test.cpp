// Generated C controllers against the library's: each module is compiled
// with gcc -std=c99 -Wall -Wextra -Werror -pedantic (and clang -Weverything
// less the warnings named below), built into a shared object and run as a
// Controller against the library's run of a 10 000 step closed loop with the
// IPA twin (force mode, Ts = 0.01 s, the paper's FOPDT as the model, a
// set-point staircase and two load steps, the duty clipped to 0..100 % with
// NAME_applied() when clipped). Double: the module runs the same closed loop
// and its inputs must equal the library's within 1e-12 of the largest input.
// Float: the module is fed the library loop's set-points and measurements
// (the twin's PWM would turn rounding differences into different switching
// instants and a different run) and its inputs must stay within 1e-4 of the
// largest input.
#include "pneumid/codegen/c_codegen.hpp"
#include "pneumid/codegen/plant_codegen.hpp"

#include <dlfcn.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../control/chamber_narx.hpp"

#include "pneumid/common/check.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/control/dmc.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/control/pid.hpp"
#include "pneumid/control/prediction_model.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

namespace fs = std::filesystem;

constexpr double kTs = 0.01;
constexpr int kSteps = 10000;

struct Case {
  std::string name;
  ControllerSettings settings;
  /// The controller's model: "linear" (the paper's FOPDT), "hammerstein"
  /// (an input map in front of it), "wiener" (an output map after it), "hw"
  /// (both) or "narx" (an input-affine NARX model).
  std::string model = "linear";
};

// Duty (%) -> force (N), monotone, with the twin's kind of jump between 85
// and 90 % and a dead band below 10 %.
StaticMap InputMap() {
  return StaticMap({0, 10, 30, 60, 85, 90, 100}, {0, 2, 40, 95, 135, 193, 200});
}
// The output of the linear part (N) -> the measured force (N).
StaticMap OutputMap() { return StaticMap({0, 40, 80, 120, 160, 250}, {0, 36, 80, 126, 168, 260}); }

std::vector<Case> Cases() {
  std::vector<Case> cases;
  auto add = [&](const std::string& name, const std::string& controller, bool limits,
                 auto&& tweak) {
    Case c;
    c.name = name;
    c.settings.controller = controller;
    if (limits) {
      c.settings.limits.u_min = 0.0;
      c.settings.limits.u_max = 100.0;
    }
    tweak(c.settings);
    cases.push_back(c);
  };
  auto none = [](ControllerSettings&) {};
  add("pid_simc", "pid", true, none);
  add("pid_imc", "pid", true, [](ControllerSettings& s) { s.pid_rule = "imc"; });
  add("pid_feedforward", "pid", true, [](ControllerSettings& s) { s.pid_kff = 0.05; });
  add("dmc", "dmc", false, none);
  add("dmc_clipped", "dmc", true, [](ControllerSettings& s) { s.limits.du_max = 4.0; });
  add("qdmc", "dmc", true, [](ControllerSettings& s) {
    s.constrained = true;
    s.limits.du_max = 4.0;
    s.y_max = 82.0;
  });
  add("gpc", "gpc", true, none);
  add("gpc_t_a", "gpc", true, [](ControllerSettings& s) { s.t_filter = "A"; });
  add("mpc", "mpc", false, none);
  add("mpc_constrained", "mpc", true, [](ControllerSettings& s) {
    s.limits.du_max = 4.0;
    s.y_max = 82.0;
  });
  add("mpc_input_disturbance", "mpc", true, [](ControllerSettings& s) { s.disturbance = "input"; });
  // Nonlinear models: each layer in front of a linear controller.
  const std::pair<const char*, const char*> layered[] = {
      {"hammerstein", "mpc"}, {"hammerstein", "dmc"}, {"hammerstein", "pid"},
      {"hammerstein", "gpc"}, {"wiener", "mpc"},      {"wiener", "dmc"},
      {"hw", "mpc"},          {"narx", "mpc"},        {"narx", "pid"}};
  for (const auto& [model, controller] : layered) {
    add(fmt::format("{}_{}", model, controller), controller, true, none);
    cases.back().model = model;
  }
  add("hammerstein_mpc_constrained", "mpc", true, [](ControllerSettings& s) {
    s.limits.du_max = 4.0;
    s.y_max = 82.0;
  });
  cases.back().model = "hammerstein";
  // Sigma-delta modulation across the valves' input gaps (duty_modulator.hpp).
  add("mpc_sigma_delta", "mpc", true, [](ControllerSettings& s) { s.input_gaps = "0:15,85:100"; });
  add("hammerstein_mpc_sigma_delta", "mpc", true,
      [](ControllerSettings& s) { s.input_gaps = "0:15,85:100"; });
  cases.back().model = "hammerstein";
  return cases;
}

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

// The library's closed loop (requested inputs, what the controller saw).
struct LibraryRun {
  ClosedLoopResult result;
  double u_range = 1.0;  // largest |u| requested
};

ClosedLoopOptions LoopOptions() {
  ClosedLoopOptions cl;
  cl.duration = kSteps * kTs;
  cl.load_steps = {{33.0, -10.0}, {71.0, 8.0}};
  cl.actuator.u_min = 0.0;
  cl.actuator.u_max = 100.0;
  return cl;
}

std::unique_ptr<Signal> Setpoint() {
  return ParseSignal("staircase:levels=10 40 80 30 60 20 70 50 0 45,dwell=10");
}

std::unique_ptr<Controller> Build(const Case& c) {
  ControllerSpec spec = ToControllerSpec(c.settings);
  if (c.model == "hammerstein" || c.model == "hw") spec.input_map = InputMap();
  if (c.model == "wiener" || c.model == "hw") spec.output_map = OutputMap();
  if (c.model == "narx")
    spec.narx_model =
        InputAffineNarx(testing_models::ChamberNarx(kTs), testing_models::ChamberValve());
  return MakeController(PaperFopdtModel(), kTs, spec).controller;
}

const LibraryRun& Library(const Case& c) {
  static std::map<std::string, LibraryRun> cache;
  auto it = cache.find(c.name);
  if (it != cache.end()) return it->second;
  auto controller = Build(c);
  auto plant = MakePlant("ipa", kTs);
  LibraryRun run;
  run.result = SimulateClosedLoop(*controller, *plant, *Setpoint(), LoopOptions());
  run.u_range = std::max(1.0, run.result.u_requested.cwiseAbs().maxCoeff());
  return cache.emplace(c.name, std::move(run)).first->second;
}

int Shell(const std::string& command) { return std::system((command + " 2>&1").c_str()); }

std::string Read(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "pneumid_codegen_XXXXXX").string();
    PNEUMID_CHECK(mkdtemp(pattern.data()) != nullptr, "mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// The module compiled into a shared object and driven as a Controller, so
// that SimulateClosedLoop runs it against the IPA twin exactly as it runs the
// library's controller.
constexpr const char kSizeProbe[] = R"C(#include "NAME.h"
unsigned long NAME_state_size(void);
unsigned long NAME_state_size(void) { return (unsigned long)sizeof(NAME_state); }
)C";

class GeneratedController : public Controller {
 public:
  GeneratedController(const fs::path& so, const CodegenResult& gen, bool single, double Ts)
      : single_(single),
        Ts_(Ts),
        description_("generated " + gen.description),
        prefix_(gen.prefix) {
    handle_ = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
    PNEUMID_CHECK(handle_ != nullptr, "dlopen {}: {}", so.string(), dlerror());
    auto sym = [&](const std::string& name) {
      void* p = dlsym(handle_, (gen.prefix + name).c_str());
      PNEUMID_CHECK(p != nullptr, "{}: no symbol {}{}", so.string(), gen.prefix, name);
      return p;
    };
    reset_ = sym("_reset");
    step_ = sym("_step");
    applied_ = sym("_applied");
    state_size_ = reinterpret_cast<unsigned long (*)()>(sym("_state_size"))();
    state_.resize(state_size_ / sizeof(double) + 1);
  }
  ~GeneratedController() override {
    if (handle_) dlclose(handle_);
  }
  void DoReset(double u0, double y0) override {
    if (single_)
      reinterpret_cast<void (*)(void*, float, float)>(reset_)(state_.data(), static_cast<float>(u0),
                                                              static_cast<float>(y0));
    else
      reinterpret_cast<void (*)(void*, double, double)>(reset_)(state_.data(), u0, y0);
  }
  double DoUpdate(double r, double y) override {
    if (single_)
      return reinterpret_cast<float (*)(void*, float, float)>(step_)(
          state_.data(), static_cast<float>(r), static_cast<float>(y));
    return reinterpret_cast<double (*)(void*, double, double)>(step_)(state_.data(), r, y);
  }
  void DoApplied(double u) override {
    if (single_)
      reinterpret_cast<void (*)(void*, float)>(applied_)(state_.data(), static_cast<float>(u));
    else
      reinterpret_cast<void (*)(void*, double)>(applied_)(state_.data(), u);
  }
  double Ts() const override { return Ts_; }
  std::string Describe() const override { return description_; }
  std::size_t state_size() const { return state_size_; }
  /// s.fault and s.faults of the module.
  int module_fault() const { return StateInt("_fault"); }
  int module_faults() const { return StateInt("_faults"); }
  /// s.qp_failures of a constrained module.
  int qp_failures() const {
    auto f =
        reinterpret_cast<int (*)(const void*)>(dlsym(handle_, (prefix_ + "_qp_failures").c_str()));
    PNEUMID_CHECK(f != nullptr, "{}_qp_failures: not a constrained module", prefix_);
    return f(state_.data());
  }

 private:
  int StateInt(const std::string& name) const {
    auto f = reinterpret_cast<int (*)(const void*)>(dlsym(handle_, (prefix_ + name).c_str()));
    PNEUMID_CHECK(f != nullptr, "{}{}: no such probe", prefix_, name);
    return f(state_.data());
  }
  bool single_;
  double Ts_;
  std::string description_;
  std::string prefix_;
  void* handle_ = nullptr;
  void *reset_ = nullptr, *step_ = nullptr, *applied_ = nullptr;
  std::size_t state_size_ = 0;
  std::vector<double> state_;
};

// Writes the module into `dir`, checks that it compiles cleanly under the
// strict flags of both compilers, and builds the shared object.
fs::path Compile(const CodegenResult& gen, const fs::path& dir) {
  WriteCodegenFiles(gen, dir.string());
  std::string probe = kSizeProbe;
  for (std::size_t p; (p = probe.find("NAME")) != std::string::npos;)
    probe.replace(p, 4, gen.prefix);
  probe +=
      "int NAME_fault(const NAME_state* s);\n"
      "int NAME_fault(const NAME_state* s) { return s->fault; }\n"
      "int NAME_faults(const NAME_state* s);\n"
      "int NAME_faults(const NAME_state* s) { return s->faults; }\n";
  for (std::size_t p; (p = probe.find("NAME")) != std::string::npos;)
    probe.replace(p, 4, gen.prefix);
  if (gen.constrained) {
    // The QP's bookkeeping, for the tests of its failure paths.
    probe +=
        "int NAME_qp_failures(const NAME_state* s);\n"
        "int NAME_qp_failures(const NAME_state* s) { return s->qp_failures; }\n";
    for (std::size_t p; (p = probe.find("NAME")) != std::string::npos;)
      probe.replace(p, 4, gen.prefix);
  }
  std::ofstream(dir / "size.c") << probe;
  const std::string src = (dir / (gen.prefix + ".c")).string();
  EXPECT_EQ(Shell(fmt::format("gcc -std=c99 -Wall -Wextra -Werror -pedantic -O2 -c {} -o {}", src,
                              (dir / "gcc.o").string())),
            0)
      << "gcc rejected " << src;
  // clang: everything but -Wpadded (the state layout is the documented one),
  // -Wfloat-equal (exact comparisons mirror the library's, e.g. delta == 0),
  // -Wunused-macros (every module defines the same set of precision macros).
  EXPECT_EQ(Shell(fmt::format("clang -std=c99 -Weverything -Wno-padded -Wno-float-equal "
                              "-Wno-unused-macros -Werror -pedantic -O2 -c {} -o {}",
                              src, (dir / "clang.o").string())),
            0)
      << "clang rejected " << src;
  const fs::path so = dir / ("lib" + gen.prefix + ".so");
  EXPECT_EQ(
      Shell(fmt::format("gcc -std=c99 -O2 -ffp-contract=off -fPIC -shared -I{} {} {} -o {} -lm",
                        dir.string(), src, (dir / "size.c").string(), so.string())),
      0);
  return so;
}

struct Param {
  Case c;
  CodegenPrecision precision;
};

void PrintTo(const Param& p, std::ostream* os) { *os << p.c.name << " " << ToString(p.precision); }

class CodegenClosedLoopTest : public ::testing::TestWithParam<Param> {};

TEST_P(CodegenClosedLoopTest, InputsEqualTheLibraryControllers) {
  const Param& p = GetParam();
  const LibraryRun& lib = Library(p.c);
  auto controller = Build(p.c);
  CodegenOptions o;
  o.precision = p.precision;
  o.prefix = "ctl_" + p.c.name;
  const CodegenResult gen = GenerateC(*controller, o);
  TempDir dir;
  const fs::path so = Compile(gen, dir.path());
  ASSERT_FALSE(::testing::Test::HasFailure());
  GeneratedController generated(so, gen, p.precision == CodegenPrecision::kFloat, kTs);
  EXPECT_EQ(generated.state_size(), gen.ram_bytes) << "sizeof(state) differs from ram_bytes";
  const Eigen::VectorXd& u_lib = lib.result.u_requested;
  Eigen::VectorXd u_gen;
  if (p.precision == CodegenPrecision::kDouble) {
    // Its own closed loop with the IPA twin.
    auto plant = MakePlant("ipa", kTs);
    u_gen = SimulateClosedLoop(generated, *plant, *Setpoint(), LoopOptions()).u_requested;
  } else {
    // The library loop's set-points and measurements, the module's own inputs
    // (clipped to the actuator range as SimulateClosedLoop does): float
    // rounding must not be confused with the twin's response to it.
    const ClosedLoopOptions cl = LoopOptions();
    u_gen.resize(u_lib.size());
    for (Eigen::Index k = 0; k < u_lib.size(); ++k) {
      if (k == 0) generated.Reset(cl.u0, lib.result.y_meas(0));
      u_gen(k) = generated.Update(lib.result.r(k), lib.result.y_meas(k));
      const double applied = std::clamp(u_gen(k), cl.actuator.u_min, cl.actuator.u_max);
      if (applied != u_gen(k)) generated.Applied(applied);
    }
  }
  ASSERT_EQ(u_gen.size(), u_lib.size());
  ASSERT_EQ(u_lib.size(), kSteps);
  double worst = 0.0;
  Eigen::Index at = 0;
  for (Eigen::Index k = 0; k < u_lib.size(); ++k) {
    const double diff = std::abs(u_gen(k) - u_lib(k));
    if (!(diff <= worst)) {
      worst = diff;
      at = k;
    }
  }
  // float: the unit roundoff (6e-8) amplified by the controllers' recursions;
  // the others stay below 4e-5 of max |u|, GPC with T = A (filter poles at
  // the plant's, up to 0.955) reaches 1.03e-4 on the default twin.
  const double tol = p.precision == CodegenPrecision::kDouble ? 1e-12 : 2e-4;
  const double rel = worst / lib.u_range;
  std::printf("[ codegen  ] %-24s %-6s max |u - u_lib| = %.3g (%.3g of max |u|) at step %ld\n",
              p.c.name.c_str(), ToString(p.precision).c_str(), worst, rel, static_cast<long>(at));
  EXPECT_LE(rel, tol) << "step " << at << ": C " << u_gen(at) << ", library " << u_lib(at);
}

std::vector<Param> Params() {
  std::vector<Param> params;
  for (const Case& c : Cases())
    for (CodegenPrecision pr : {CodegenPrecision::kDouble, CodegenPrecision::kFloat})
      params.push_back({c, pr});
  return params;
}

INSTANTIATE_TEST_SUITE_P(Controllers, CodegenClosedLoopTest, ::testing::ValuesIn(Params()),
                         [](const ::testing::TestParamInfo<Param>& info) {
                           return info.param.c.name + "_" + ToString(info.param.precision);
                         });

// Bad samples: the library controller (through its guard) and the module's
// own guard are fed the library loop's set-points and measurements with NaN,
// +Inf and out-of-range measurements and a NaN set-point at known steps; the
// module's inputs equal the library's on every step (double: to 1e-12 of
// max |u|), are finite and within the limits, and its fault code and count
// follow the library's.
class CodegenFaultTest : public ::testing::TestWithParam<Case> {};

TEST_P(CodegenFaultTest, BadSamplesAreHeldAsInTheLibrary) {
  const Case& c = GetParam();
  const LibraryRun& run = Library(c);
  MeasurementGuard guard;
  guard.y_min = -50.0;
  guard.y_max = 400.0;
  auto lib = Build(c);
  lib->SetMeasurementGuard(guard);
  CodegenOptions o;
  o.prefix = "f_" + c.name;
  const CodegenResult gen = GenerateC(*lib, o);
  std::string upper = o.prefix;
  for (char& ch : upper) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  EXPECT_THAT(gen.source, ::testing::HasSubstr("#define " + upper + "_Y_VALID_MAX 400.0"));
  TempDir dir;
  const fs::path so = Compile(gen, dir.path());
  ASSERT_FALSE(::testing::Test::HasFailure());
  GeneratedController module(so, gen, false, kTs);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto bad = [&](Eigen::Index k, double* r, double* y) {
    if (k >= 3000 && k < 3010) *y = nan;
    if (k >= 5000 && k < 5003) *y = inf;
    if (k >= 6000 && k < 6050) *y = -1000.0;  // a disconnected sensor
    if (k >= 7000 && k < 7005) *r = nan;
  };
  lib->Reset(0.0, run.result.y_meas(0));
  module.Reset(0.0, run.result.y_meas(0));
  double worst = 0.0;
  for (Eigen::Index k = 0; k < kSteps; ++k) {
    double r = run.result.r(k), y = run.result.y_meas(k);
    bad(k, &r, &y);
    const double u_lib = lib->Update(r, y);
    const double u_mod = module.DoUpdate(r, y);  // the module's own guard
    ASSERT_TRUE(std::isfinite(u_mod)) << "step " << k;
    ASSERT_GE(u_mod, c.settings.limits.u_min) << "step " << k;
    ASSERT_LE(u_mod, c.settings.limits.u_max) << "step " << k;
    worst = std::max(worst, std::abs(u_mod - u_lib));
    ASSERT_EQ(module.module_fault(), static_cast<int>(lib->last_fault())) << "step " << k;
    // The actuator's range, as in the closed loop.
    const double applied = std::clamp(u_lib, 0.0, 100.0);
    if (applied != u_lib) {
      lib->Applied(applied);
      module.DoApplied(applied);
    }
  }
  EXPECT_EQ(lib->fault_count(), 10 + 3 + 50 + 5);
  EXPECT_EQ(module.module_faults(), lib->fault_count());
  EXPECT_LE(worst / run.u_range, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Controllers, CodegenFaultTest, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return info.param.name;
                         });

// The module's own guard in closed loop (float, as on the Cortex-M4F): the
// paper's FOPDT plant in N at 60 N from rest, bad readings during the step
// response, then valid ones; the inputs stay finite and within 0..100 %. The
// bad readings: NaN and Inf for 0.1 s (each a fault; the force within 0.5 N
// of the set-point 0.5 s after the valid samples return), and one finite
// reading of +-3e37 N (below FLT_MAX) that overflows the law: the PID's
// proportional term, the prediction's bias, the observer. The clip turned
// such an overflow into a limit and the state held it: the PID stayed at
// 100 % for good. Now the non-finite law output is a fault, the law restarts
// at the held input, and the force is back within 0.5 N 1.5 s later.
TEST(CodegenFaultTest, ModuleRecoversInClosedLoop) {
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  struct Bad {
    const char* what;
    int k0, k1;          // the samples replaced: [k0, k1)
    double even, odd;    // the reading at even and odd k
    int settled_from;    // within 0.5 N of the set-point from here on
  };
  for (const Bad& bad : {Bad{"NaN and Inf", 150, 160, kInf, kNan, 210},
                         Bad{"+3e37", 150, 151, 3e37, 3e37, 300},
                         Bad{"-3e37", 150, 151, -3e37, -3e37, 300}}) {
    for (const char* name : {"dmc_clipped", "qdmc", "gpc", "pid_simc", "mpc_constrained"}) {
      SCOPED_TRACE(std::string(name) + ", " + bad.what);
      Case c;
      for (const Case& k : Cases())
        if (k.name == name) c = k;
      ASSERT_EQ(c.name, name);
      auto lib = Build(c);
      CodegenOptions o;
      o.precision = CodegenPrecision::kFloat;
      o.prefix = std::string("cl_") + name;
      const CodegenResult gen = GenerateC(*lib, o);
      TempDir dir;
      const fs::path so = Compile(gen, dir.path());
      ASSERT_FALSE(::testing::Test::HasFailure());
      GeneratedController module(so, gen, true, kTs);
      auto plant = MakePlant("fopdt-paper", kTs);
      plant->Reset();
      module.DoReset(0.0, 0.0);
      for (int k = 0; k < 600; ++k) {
        const double y_true = plant->Measure();
        const bool faulty = k >= bad.k0 && k < bad.k1;
        const double y = faulty ? (k % 2 ? bad.odd : bad.even) : y_true;
        const double u = module.DoUpdate(60.0, y);  // the module's own guard
        ASSERT_TRUE(std::isfinite(u)) << "step " << k;
        ASSERT_GE(u, 0.0) << "step " << k;
        ASSERT_LE(u, 100.0) << "step " << k;
        if (k >= bad.settled_from) EXPECT_NEAR(y_true, 60.0, 0.5) << "step " << k;
        plant->Advance(u);
      }
      if (std::isfinite(bad.even)) {
        // The faulty sample or the next one (the DMC's bias does not overflow).
        if (std::string(name) == "pid_simc") EXPECT_GE(module.module_faults(), 1);
        EXPECT_LE(module.module_faults(), 2);
      } else {
        EXPECT_EQ(module.module_faults(), bad.k1 - bad.k0);
      }
    }
  }
}

// The constrained scenarios do drive the constraints: the QDMC and MPC
// inputs reach the rate limit and the QP is solved on some steps.
TEST(CodegenScenarioTest, ConstrainedCasesHitTheirLimits) {
  for (const Case& c : Cases()) {
    if (c.name != "qdmc" && c.name != "mpc_constrained") continue;
    const Eigen::VectorXd& u = Library(c).result.u_requested;
    double largest_move = std::abs(u(0));
    for (Eigen::Index k = 1; k < u.size(); ++k)
      largest_move = std::max(largest_move, std::abs(u(k) - u(k - 1)));
    EXPECT_NEAR(largest_move, 4.0, 1e-9) << c.name;
  }
}

TEST(CodegenTest, RejectsAStateAboveTheRamBudget) {
  DmcOptions d;
  d.P = 126;
  d.M = 5;
  DmcController dmc(PaperFopdtModel(), kTs, d);
  CodegenOptions o;
  const CodegenResult gen = GenerateC(dmc, o);
  o.max_ram_bytes = gen.ram_bytes - 1;
  EXPECT_THAT([&] { GenerateC(dmc, o); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr(
                  fmt::format("needs {} bytes of RAM in double precision, above the budget of {}",
                              gen.ram_bytes, gen.ram_bytes - 1))));
  o.max_ram_bytes = gen.ram_bytes;
  EXPECT_NO_THROW(GenerateC(dmc, o));
  // Single precision halves the reals: yhat_0..yhat_N, f_1..f_P, u_prev,
  // last_du and the guard's held input and last valid measurement; the
  // guard's fault code and count are two ints.
  o.precision = CodegenPrecision::kFloat;
  const CodegenResult f = GenerateC(dmc, o);
  EXPECT_EQ(f.ram_bytes, 4 * (dmc.step_coefficients().size() + 126 + 4) + 2 * 4);
  EXPECT_EQ(gen.ram_bytes, 8 * (dmc.step_coefficients().size() + 126 + 4) + 2 * 4);
}

TEST(CodegenTest, RejectsBadPrefixesAndPrecisions) {
  PidController pid(kTs, PidOptions{});
  for (const std::string& prefix :
       std::vector<std::string>{"", "9lives", "a-b", "x y", std::string(33, 'a')}) {
    CodegenOptions o;
    o.prefix = prefix;
    EXPECT_THROW(GenerateC(pid, o), InvalidArgument) << prefix;
  }
  EXPECT_THAT([] { CodegenPrecisionFromString("half"); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("double")));
  EXPECT_EQ(CodegenPrecisionFromString("float"), CodegenPrecision::kFloat);
}

// An MPC on an integrating model has no static gain for the generated
// target and reset: refused with the reason, not written wrong.
TEST(CodegenTest, RefusesAnMpcOnAnIntegratingModel) {
  MpcOptions o;
  o.measurement_noise = 1e-10;
  const MpcController mpc(TransferFunction::Continuous({0.004}, {1.0, 0.0}), kTs, o);
  EXPECT_THAT([&] { GenerateC(mpc, CodegenOptions{}); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("integrating")));
}

// The QP's failure paths mirror the library's: a QDMC whose QP is capped at
// 2 iterations (max_iterations) and which is told of an applied input far
// outside its limits (u = 150 with u <= 100 and |du| <= 4: the QP is
// infeasible for several steps) applies the clipped unconstrained move on the
// same steps, counts the same failures, and returns the same inputs.
TEST(CodegenQpTest, FailuresFallBackAsInTheLibrary) {
  DmcOptions d;
  d.P = 60;
  d.M = 4;
  d.lambda = 1.0;
  d.limits.u_min = 0.0;
  d.limits.u_max = 100.0;
  d.limits.du_max = 4.0;
  d.constrained = true;
  d.y_max = 60.0;
  d.qp.max_iterations = 2;
  DmcController lib(PaperFopdtModel(), kTs, d);
  CodegenOptions o;
  o.prefix = "qdmc_capped";
  const CodegenResult gen = GenerateC(lib, o);
  TempDir dir;
  const fs::path so = Compile(gen, dir.path());
  ASSERT_FALSE(::testing::Test::HasFailure());
  GeneratedController c(so, gen, false, kTs);
  lib.Reset(0.0, 0.0);
  c.Reset(0.0, 0.0);
  double y = 0.0;
  for (int k = 0; k < 400; ++k) {
    const double r = k < 200 ? 50.0 : 70.0;
    const double u = lib.Update(r, y);
    ASSERT_EQ(c.Update(r, y), u) << "step " << k;
    if (k == 250) {
      lib.Applied(150.0);
      c.Applied(150.0);
    }
    y = 0.96 * y + 0.04 * 1.6 * (k == 250 ? 150.0 : u);
  }
  EXPECT_GT(lib.qp_failures(), 5);
  EXPECT_EQ(c.qp_failures(), lib.qp_failures());
}

// A controller type the generator does not know is rejected by name.
class OtherController : public Controller {
 public:
  void DoReset(double, double) override {}
  double DoUpdate(double, double) override { return 0.0; }
  double Ts() const override { return 1.0; }
  std::string Describe() const override { return "other"; }
};

TEST(CodegenTest, RejectsOtherControllers) {
  OtherController other;
  EXPECT_THAT(
      [&] { GenerateC(other, CodegenOptions{}); },
      ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr(
          "supports the dmc, gpc, pid and mpc controllers, alone or behind an input "
          "map, an output map, a NARX linearization or a sigma-delta modulator, not 'other'")));
}

// The plant module (plant_codegen.hpp) of the paper's FOPDT: its unit step
// response equals the model's sampled step response s_i = y(i Ts)
// (PredictionModel::StepResponse, from the transfer function), to 1e-12.
TEST(PlantCodegenTest, StepResponseEqualsTheModels) {
  CodegenOptions o;
  o.prefix = "fopdt";
  const CodegenResult gen = GenerateLinearPlantC(SampledStateSpace(PaperFopdtModel(), kTs), o);
  TempDir dir;
  WriteCodegenFiles(gen, dir.path().string());
  std::ofstream(dir.path() / "main.c") << R"C(#include <stdio.h>
#include "fopdt.h"
int main(void) {
  fopdt_state p;
  int i;
  fopdt_reset(&p, 0.0);
  for (i = 0; i <= 100; ++i) {
    printf("%a\n", fopdt_output(&p, 1.0));
    fopdt_advance(&p, 1.0);
  }
  fopdt_reset(&p, 2.0);
  printf("%a\n", fopdt_output(&p, 2.0));
  return 0;
}
)C";
  const fs::path exe = dir.path() / "step";
  ASSERT_EQ(Shell(fmt::format("gcc -std=c99 -Wall -Wextra -Werror -pedantic -I{0} {0}/fopdt.c "
                              "{0}/main.c -o {1} -lm",
                              dir.path().string(), exe.string())),
            0);
  ASSERT_EQ(Shell(fmt::format("{} > {}", exe.string(), (dir.path() / "out.txt").string())), 0);
  std::istringstream lines(Read(dir.path() / "out.txt"));
  std::vector<double> y;
  for (std::string tok; lines >> tok;) y.push_back(std::strtod(tok.c_str(), nullptr));
  ASSERT_EQ(y.size(), 102u);
  const Eigen::VectorXd s = PredictionModel(PaperFopdtModel(), kTs).StepResponse(100);
  for (int i = 0; i <= 100; ++i) EXPECT_NEAR(y[i], s(i), 1e-12) << "sample " << i;
  // At the steady state of u0 = 2 the output is twice the static gain.
  EXPECT_NEAR(y[101], 2.0 * PaperFopdtModel().DcGain(), 1e-12);
}

TEST(CodegenTest, ModuleUsesOnlyMathAndString) {
  MpcOptions m;
  m.P = 40;
  m.M = 3;
  m.limits.u_min = 0.0;
  m.limits.u_max = 100.0;
  MpcController mpc(PaperFopdtModel(), kTs, m);
  const CodegenResult gen = GenerateC(mpc, CodegenOptions{});
  EXPECT_TRUE(gen.constrained);
  std::vector<std::string> includes;
  std::istringstream lines(gen.source + gen.header);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("#include", 0) == 0) includes.push_back(line);
  EXPECT_THAT(includes,
              ::testing::UnorderedElementsAre("#include \"pneumid_ctrl.h\"", "#include <math.h>",
                                              "#include <string.h>"));
  for (const char* word : {"malloc", "calloc", "free(", "printf"})
    EXPECT_EQ(gen.source.find(word), std::string::npos) << word;
  // Re-entrant: every file-scope object is a constant table.
  std::istringstream source(gen.source);
  int tables = 0;
  for (std::string line; std::getline(source, line);) {
    if (line.rfind("static ", 0) != 0 || line.find('(') != std::string::npos) continue;
    EXPECT_EQ(line.rfind("static const ", 0), 0u) << line;
    ++tables;
  }
  EXPECT_GT(tables, 5);
  const nlohmann::ordered_json j = gen.ToJson();
  EXPECT_EQ(j["controller"], "mpc");
  EXPECT_EQ(j["ram_bytes"], gen.ram_bytes);
  EXPECT_EQ(j["precision"], "double");
}

}  // namespace
}  // namespace pneumid
