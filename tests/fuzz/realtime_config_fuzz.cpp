// The real-time configuration TOML (realtime/realtime_config).
#include "fuzz_support.hpp"
#include "pneumid/realtime/realtime_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pneumid;
  fuzz::Expect([&] { ParseRealtimeConfig(std::string(fuzz::AsText(data, size)), "fuzz.toml"); });
  return 0;
}
