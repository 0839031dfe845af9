// Shared pieces of the libFuzzer targets (tests/fuzz/*_fuzz.cpp).
//
// A target feeds one input to a parser and accepts the documented errors
// (pneumid::DataError for bad content, pneumid::InvalidArgument for a bad
// spec); any other exception, a crash, a sanitizer report, a leak, a hang
// beyond -timeout or memory beyond -rss_limit_mb is a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "pneumid/common/check.hpp"

namespace pneumid::fuzz {

/// The input as text.
inline std::string_view AsText(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// One scratch file per process, named with `suffix` (the readers choose the
/// format by extension); Write replaces its content.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& suffix) {
    const char* dir = std::getenv("TMPDIR");
    path_ = std::string(dir != nullptr && *dir != '\0' ? dir : "/tmp") + "/pneumid-fuzz-" +
            std::to_string(::getpid()) + suffix;
  }
  ~ScratchFile() { std::remove(path_.c_str()); }

  const std::string& Write(const std::uint8_t* data, std::size_t size) const {
    std::FILE* f = std::fopen(path_.c_str(), "wb");
    if (f == nullptr) std::abort();
    if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
    return path_;
  }

 private:
  std::string path_;
};

/// Runs f, accepting the library's documented errors.
template <typename F>
void Expect(F&& f) {
  try {
    f();
  } catch (const DataError&) {
  } catch (const InvalidArgument&) {
  }
}

}  // namespace pneumid::fuzz
