// Read-only memory map of a whole file, shared by the CSV and MAT readers.
#pragma once

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid::internal {

/// Maps the pages of [p, p + bytes) in one system call (MADV_POPULATE_READ /
/// _WRITE, Linux 5.14) instead of one page fault per 4 KiB page on first
/// access, and asks for transparent huge pages for memory to be written. On
/// kernels without these calls nothing happens and the pages fault in as usual.
inline void PopulatePages(void* p, std::size_t bytes, bool write) {
  const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  const auto begin = (reinterpret_cast<std::uintptr_t>(p) + page - 1) / page * page;
  const auto end = (reinterpret_cast<std::uintptr_t>(p) + bytes) / page * page;
  if (end <= begin) return;
  void* const first = reinterpret_cast<void*>(begin);
#ifdef MADV_HUGEPAGE
  if (write) ::madvise(first, end - begin, MADV_HUGEPAGE);
#endif
#if defined(MADV_POPULATE_READ) && defined(MADV_POPULATE_WRITE)
  ::madvise(first, end - begin, write ? MADV_POPULATE_WRITE : MADV_POPULATE_READ);
#endif
}

/// Read-only view of a whole file, memory-mapped (or empty for an empty file).
class MappedFile {
 public:
  explicit MappedFile(const std::string& path) {
    fd_ = ::open(path.c_str(), O_RDONLY);
    if (fd_ < 0) {
      throw DataError(fmt::format("{}: cannot open: {}", path, std::strerror(errno)));
    }
    struct stat st {};
    if (::fstat(fd_, &st) != 0) {
      const int e = errno;
      ::close(fd_);
      throw DataError(fmt::format("{}: cannot read: {}", path, std::strerror(e)));
    }
    if (S_ISDIR(st.st_mode)) {
      ::close(fd_);
      throw DataError(fmt::format("{}: is a directory, not a data file", path));
    }
    size_ = static_cast<std::size_t>(st.st_size);
    if (size_ > 0) {
      void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd_, 0);
      if (p == MAP_FAILED) {
        const int e = errno;
        ::close(fd_);
        throw DataError(fmt::format("{}: cannot map: {}", path, std::strerror(e)));
      }
      ::madvise(p, size_, MADV_SEQUENTIAL);
      data_ = static_cast<const char*>(p);
    }
  }
  ~MappedFile() {
    if (data_ != nullptr) ::munmap(const_cast<char*>(data_), size_);
    if (fd_ >= 0) ::close(fd_);
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  std::string_view view() const { return {data_ == nullptr ? "" : data_, size_}; }

 private:
  int fd_ = -1;
  const char* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace pneumid::internal
