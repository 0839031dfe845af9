// The fuzz corpus as a regression test: every committed input of
// tests/fuzz/corpus/<target>/ is fed once to that target's entry point (the
// same code libFuzzer runs, tests/fuzz/*_fuzz.cpp, compiled with its
// LLVMFuzzerTestOneInput renamed to PneumidFuzzReplay_<target>). The parsers
// must answer with their documented errors only: any other exception fails
// the test naming the file; a crash fails it too (and, in the sanitizer
// build, any report). No libFuzzer or clang is needed.
//
// Usage: pneumid_fuzz_replay TARGET DIR_OR_FILE...
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#define PNEUMID_FUZZ_TARGETS(X) \
  X(csv) X(mat) X(model) X(signal) X(udp) X(realtime_config) X(ipa_config)
#define PNEUMID_DECLARE(t) \
  extern "C" int PneumidFuzzReplay_##t(const std::uint8_t* data, std::size_t size);
PNEUMID_FUZZ_TARGETS(PNEUMID_DECLARE)
#undef PNEUMID_DECLARE

namespace {

using Entry = int (*)(const std::uint8_t*, std::size_t);

std::vector<std::filesystem::path> Inputs(const std::filesystem::path& arg) {
  std::vector<std::filesystem::path> files;
  if (std::filesystem::is_directory(arg)) {
    for (const auto& e : std::filesystem::directory_iterator(arg))
      if (e.is_regular_file()) files.push_back(e.path());
  } else {
    files.push_back(arg);
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

int main(int argc, char** argv) {
  const std::map<std::string, Entry> targets = {
#define PNEUMID_ENTRY(t) {#t, &PneumidFuzzReplay_##t},
      PNEUMID_FUZZ_TARGETS(PNEUMID_ENTRY)
#undef PNEUMID_ENTRY
  };
  if (argc < 3 || targets.count(argv[1]) == 0) {
    std::cerr << "usage: pneumid_fuzz_replay TARGET DIR_OR_FILE...  (TARGET: ";
    for (const auto& [name, entry] : targets) std::cerr << name << " ";
    std::cerr << ")\n";
    return 2;
  }
  const Entry entry = targets.at(argv[1]);
  int replayed = 0, failed = 0;
  for (int a = 2; a < argc; ++a) {
    if (!std::filesystem::exists(argv[a])) {
      std::cerr << argv[a] << ": no such file or directory\n";
      ++failed;
      continue;
    }
    for (const auto& path : Inputs(argv[a])) {
      std::ifstream in(path, std::ios::binary);
      const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                    std::istreambuf_iterator<char>());
      try {
        entry(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
      } catch (const std::exception& e) {
        std::cerr << path.string() << ": undocumented exception: " << e.what() << "\n";
        ++failed;
      } catch (...) {
        std::cerr << path.string() << ": undocumented exception of unknown type\n";
        ++failed;
      }
      ++replayed;
    }
  }
  std::cout << argv[1] << ": " << replayed << " inputs replayed, " << failed << " failed\n";
  if (replayed == 0) std::cerr << "no inputs found\n";
  return failed == 0 && replayed > 0 ? 0 : 1;
}
