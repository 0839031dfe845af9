// ReadMat on arbitrary file content (through matio, after pneumid's own check
// of the sizes a MAT v5 file claims), by variable name and by column index.
#include "fuzz_support.hpp"
#include "pneumid/data/matfile.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pneumid;
  static const fuzz::ScratchFile file(".mat");
  const std::string& path = file.Write(data, size);
  fuzz::Expect([&] { ReadMat(path); });
  MatReadOptions by_index;
  by_index.time_variable = "0";
  by_index.input_variables = {"1"};
  by_index.output_variables = {"2"};
  fuzz::Expect([&] { ReadMat(path, by_index); });
  return 0;
}
