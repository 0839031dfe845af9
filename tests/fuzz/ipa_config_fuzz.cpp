// The IPA plant parameter TOML file (plant/ipa_parameters).
#include "fuzz_support.hpp"
#include "pneumid/plant/ipa_simulator.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pneumid;
  static const fuzz::ScratchFile file(".toml");
  const std::string& path = file.Write(data, size);
  fuzz::Expect([&] { LoadIpaParameters(path); });
  return 0;
}
