// ReadCsv on arbitrary file content, with the default selection (t, u, y by
// name) and with columns by index and a sample time.
#include "fuzz_support.hpp"
#include "pneumid/data/csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pneumid;
  static const fuzz::ScratchFile file(".csv");
  const std::string& path = file.Write(data, size);
  fuzz::Expect([&] { ReadCsv(path); });
  CsvReadOptions by_index;
  by_index.sample_time = 0.01;
  by_index.input_columns = {"0"};
  by_index.output_columns = {"1", "2"};
  fuzz::Expect([&] { ReadCsv(path, by_index); });
  return 0;
}
