// Model specs (models/model_file): the input is an inline spec ("tf:num=...",
// "fopdt:K=..."), or, when it starts with '{' or '[', the content of a model
// JSON file.
#include "fuzz_support.hpp"
#include "pneumid/models/model_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pneumid;
  static const fuzz::ScratchFile file(".json");
  const std::string_view text = fuzz::AsText(data, size);
  if (!text.empty() && (text.front() == '{' || text.front() == '[')) {
    const std::string& path = file.Write(data, size);
    fuzz::Expect([&] { ParseModelSpec(path); });
    fuzz::Expect([&] { ParseModelSpec(path + "#arx"); });
    return 0;
  }
  // Inline specs only: a spec naming a file would read whatever file it names.
  if (text.find('/') != std::string_view::npos || text.find('.') == 0) return 0;
  fuzz::Expect([&] {
    const TransferFunction g = ParseModelSpec(std::string(text));
    (void)ToJson(g);
  });
  return 0;
}
