// Double dispatch over the controller classes (ControllerVisitor): each
// controller the factory builds arrives at the Visit of its own class, a
// layer's inner controller at its own when the visitor descends, and a
// controller class of a user's own at VisitOther.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pneumid/control/controller.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/control/dmc.hpp"
#include "pneumid/control/duty_modulator.hpp"
#include "pneumid/control/gpc.hpp"
#include "pneumid/control/inverse_map_controller.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/control/narx_linearizing_controller.hpp"
#include "pneumid/control/pid.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid {
namespace {

// Records the class names it visits, descending into layers.
class Recorder final : public ControllerVisitor {
 public:
  std::vector<std::string> seen;
  void Visit(const PidController&) override { seen.push_back("pid"); }
  void Visit(const DmcController&) override { seen.push_back("dmc"); }
  void Visit(const GpcController&) override { seen.push_back("gpc"); }
  void Visit(const MpcController&) override { seen.push_back("mpc"); }
  void Visit(const InverseMapController& c) override {
    seen.push_back("input-map");
    c.inner().Accept(*this);
  }
  void Visit(const OutputMapController& c) override {
    seen.push_back("output-map");
    c.inner().Accept(*this);
  }
  void Visit(const ModulatedController& c) override {
    seen.push_back("sigma-delta");
    c.inner().Accept(*this);
  }
  void Visit(const NarxLinearizingController& c) override {
    seen.push_back("narx");
    c.inner().Accept(*this);
  }
  void VisitOther(const Controller&) override { seen.push_back("other"); }
};

std::vector<std::string> Visited(const Controller& controller) {
  Recorder recorder;
  controller.Accept(recorder);
  return recorder.seen;
}

TEST(ControllerVisitorTest, EachClassArrivesAtItsOwnVisit) {
  const TransferFunction model = PaperFopdtModel();
  for (const std::string type : {"dmc", "gpc", "pid", "mpc"}) {
    ControllerSettings settings;
    settings.controller = type;
    const BuiltController built = MakeController(model, 0.01, ToControllerSpec(settings));
    EXPECT_EQ(Visited(*built.controller), std::vector<std::string>{type});
  }
}

TEST(ControllerVisitorTest, LayersArriveOutsideIn) {
  ControllerSettings settings;
  settings.controller = "mpc";
  settings.limits.u_min = 0.0;
  settings.limits.u_max = 100.0;
  settings.input_gaps = "0:15,85:100";
  const BuiltController modulated =
      MakeController(PaperFopdtModel(), 0.01, ToControllerSpec(settings));
  EXPECT_EQ(Visited(*modulated.controller), (std::vector<std::string>{"sigma-delta", "mpc"}));
  ControllerSpec spec = ToControllerSpec(settings);
  spec.input_gaps.clear();
  spec.input_map = StaticMap({0.0, 50.0, 100.0}, {0.0, 40.0, 160.0});
  const BuiltController mapped = MakeController(PaperFopdtModel(), 0.01, spec);
  EXPECT_EQ(Visited(*mapped.controller), (std::vector<std::string>{"input-map", "mpc"}));
}

// A controller class of a user's own: the toolkit's visitors see it as "other".
class HoldController final : public Controller {
 public:
  double Ts() const override { return 0.01; }
  std::string Describe() const override { return "hold"; }

 protected:
  void DoReset(double, double) override {}
  double DoUpdate(double, double) override { return 0.0; }
};

TEST(ControllerVisitorTest, OtherClassesArriveAtVisitOther) {
  EXPECT_EQ(Visited(HoldController{}), std::vector<std::string>{"other"});
}

}  // namespace
}  // namespace pneumid
