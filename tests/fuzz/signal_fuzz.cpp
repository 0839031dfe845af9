// Signal specs (plant/signal) parsed and evaluated at a few instants.
#include "fuzz_support.hpp"
#include "pneumid/plant/signal.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pneumid;
  const std::string_view text = pneumid::fuzz::AsText(data, size);
  // file: specs read the file they name; the data readers have their own targets.
  if (text.find("file") != std::string_view::npos) return 0;
  fuzz::Expect([&] {
    const auto s = ParseSignal(std::string(text));
    for (const double t : {0.0, 0.01, 0.5, 1.0, 10.0}) (void)(*s)(t);
    (void)s->ToString();
  });
  return 0;
}
