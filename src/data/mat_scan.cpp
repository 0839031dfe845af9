#include "mat_scan.hpp"

#include <zlib.h>

#include <bit>
#include <cstdint>
#include <cstring>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid::internal {
namespace {

// MAT v5 data types and array classes used below (MAT-File Format, tables 1-1, 1-3).
constexpr std::uint32_t kMiInt8 = 1;
constexpr std::uint32_t kMiInt32 = 5;
constexpr std::uint32_t kMiUint32 = 6;
constexpr std::uint32_t kMiMatrix = 14;
constexpr std::uint32_t kMiCompressed = 15;
constexpr std::uint32_t kClassCell = 1;
constexpr std::uint32_t kClassStruct = 2;
constexpr std::uint32_t kClassObject = 3;
constexpr std::uint32_t kClassSparse = 5;
constexpr std::uint32_t kClassFunction = 16;
constexpr std::uint32_t kClassOpaque = 17;
constexpr int kMaxDepth = 32;
// zlib cannot expand data by more than about 1032:1.
constexpr double kMaxInflateRatio = 1100.0;
// Bytes of a compressed variable inflated to check its header.
constexpr std::size_t kInflatePrefix = 64 * 1024;

/// One data element: its type, the size its tag claims, and its data.
struct Element {
  std::uint32_t type = 0;
  std::uint64_t nbytes = 0;      ///< as claimed by the tag
  std::string_view data;         ///< the claimed bytes that are present
  std::size_t size_on_disk = 0;  ///< tag + data + padding to 8 bytes
  bool small = false;            ///< small data element format (data in the tag)
};

class Scanner {
 public:
  Scanner(const std::string& path, bool swap) : path_(path), swap_(swap) {}

  MatScan ScanFile(std::string_view bytes) {
    MatScan scan;
    scan.v5 = true;
    std::size_t offset = 128;
    for (int index = 1; offset < bytes.size(); ++index) {
      index_ = index;
      name_.clear();
      top_ = MatScanVariable{};
      const std::string_view rest = bytes.substr(offset);
      if (rest.size() < 8) {
        Fail(
            fmt::format("the file ends inside the tag of variable {} ({} bytes left at offset "
                        "{}): the file is truncated",
                        index, rest.size(), offset));
      }
      const Element e = ReadTag(rest);
      if (e.type == kMiCompressed) {
        CheckCompressed(e, offset, bytes.size());
      } else if (e.type == kMiMatrix) {
        if (e.nbytes > rest.size() - 8) {
          PeekName(e.data);
          Truncated(e, offset, bytes.size());
        }
        CheckMatrix(e.data, e.nbytes, /*partial=*/false, 0);
      } else if (e.nbytes > rest.size() - 8) {
        Truncated(e, offset, bytes.size());
      }
      const std::size_t size = e.type == kMiCompressed
                                   ? 8 + static_cast<std::size_t>(e.nbytes)
                                   : std::min<std::size_t>(e.size_on_disk, rest.size());
      top_.offset = offset;
      top_.size = size;
      scan.variables.push_back(std::move(top_));
      offset += size;
    }
    return scan;
  }

 private:
  std::uint32_t U32(std::string_view s, std::size_t at) const {
    std::uint32_t v = 0;
    std::memcpy(&v, s.data() + at, 4);
    return swap_ ? __builtin_bswap32(v) : v;
  }

  /// The element at the start of `s` (at least 8 bytes); data is cut to what
  /// `s` holds.
  Element ReadTag(std::string_view s) const {
    Element e;
    const std::uint32_t w0 = U32(s, 0);
    if ((w0 >> 16) != 0) {  // small data element: 2-byte size, data in the tag
      e.type = w0 & 0xFFFF;
      e.nbytes = w0 >> 16;
      // matio reads the claimed bytes past the tag (a small dimensions
      // element claiming 2048 bytes made it allocate 2.5 GB).
      if (e.nbytes > 4)
        Fail(
            fmt::format("{}: a small data element (type {}) claims {} bytes, more than the 4 its "
                        "tag holds: the file is corrupt",
                        Variable(), e.type, e.nbytes));
      e.data = s.substr(4, std::min<std::uint64_t>(e.nbytes, 4));
      e.size_on_disk = 8;
      e.small = true;
      return e;
    }
    e.type = w0;
    e.nbytes = U32(s, 4);
    e.data = s.substr(8, std::min<std::uint64_t>(e.nbytes, s.size() - 8));
    e.size_on_disk = 8 + static_cast<std::size_t>((e.nbytes + 7) / 8 * 8);
    return e;
  }

  [[noreturn]] void Fail(const std::string& what) const {
    throw DataError(fmt::format("{}: {}", path_, what));
  }

  std::string Variable() const {
    return name_.empty() ? fmt::format("variable {}", index_)
                         : fmt::format("variable {} ('{}')", index_, name_);
  }

  [[noreturn]] void Truncated(const Element& e, std::size_t offset, std::size_t file_size) const {
    Fail(
        fmt::format("{} needs {} bytes from offset {} but the file ends at byte {}: the file "
                    "is truncated (or not a MAT file)",
                    Variable(), 8 + e.nbytes, offset, file_size));
  }

  /// Sets name_ from the name subelement of matrix data, when it is there.
  void PeekName(std::string_view matrix) {
    std::size_t at = 0;
    for (int k = 0; k < 3 && matrix.size() - at >= 8; ++k) {
      const Element e = ReadTag(matrix.substr(at));
      if (k == 2 && e.type == kMiInt8) name_ = Excerpt(e.data);
      at += e.size_on_disk;
      if (at > matrix.size()) return;
    }
  }

  void CheckCompressed(const Element& e, std::size_t offset, std::size_t file_size) {
    const bool truncated = e.nbytes > file_size - offset - 8;
    std::string head(kInflatePrefix, '\0');
    z_stream z{};
    if (inflateInit(&z) != Z_OK) Fail("cannot initialise zlib");
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(e.data.data()));
    z.avail_in = static_cast<uInt>(e.data.size());
    z.next_out = reinterpret_cast<Bytef*>(head.data());
    z.avail_out = static_cast<uInt>(head.size());
    const int rc = inflate(&z, Z_SYNC_FLUSH);
    const std::string zlib_message = z.msg == nullptr ? "" : z.msg;
    head.resize(head.size() - z.avail_out);
    inflateEnd(&z);
    if (head.size() >= 8) PeekName(ReadTag(head).data);
    if (truncated) Truncated(e, offset, file_size);
    if (rc != Z_OK && rc != Z_STREAM_END && rc != Z_BUF_ERROR) {
      Fail(fmt::format("{}: the compressed data is corrupt (zlib: {})", Variable(),
                       zlib_message.empty() ? fmt::format("error {}", rc) : zlib_message));
    }
    if (head.size() < 8) return;  // matio reports what is missing
    const Element inner = ReadTag(head);
    if (inner.type != kMiMatrix) return;
    const double limit = kMaxInflateRatio * static_cast<double>(e.nbytes) + 1024.0;
    if (static_cast<double>(inner.nbytes) > limit) {
      Fail(
          fmt::format("{} claims {} bytes after decompression, more than its {} compressed "
                      "bytes can hold: the file is corrupt",
                      Variable(), inner.nbytes, e.nbytes));
    }
    CheckMatrix(inner.data, inner.nbytes, /*partial=*/true, 0);
  }

  /// Checks an miMATRIX element whose data claims `nbytes`; `data` holds the
  /// claimed bytes, or (partial) only their start.
  void CheckMatrix(std::string_view data, std::uint64_t nbytes, bool partial, int depth) {
    if (nbytes == 0) {
      // An empty cell element or struct field; a variable has at least its
      // flags, dimensions and name, and matio reads them from the bytes that
      // follow an empty one (their "dimensions" made it ask for 3.4 GB).
      if (depth == 0)
        Fail(
            fmt::format("{}: an array of 0 bytes, without the flags, dimensions and name "
                        "every variable has: the file is corrupt",
                        Variable()));
      return;
    }
    if (depth > kMaxDepth) {
      Fail(fmt::format("{}: arrays nested more than {} deep: the file is corrupt", Variable(),
                       kMaxDepth));
    }
    std::size_t at = 0;
    std::uint32_t cls = 0;
    double elements = 1.0;
    std::string dims;
    std::uint64_t field_name_length = 0;
    double fields = 1.0;
    for (int k = 0; at < data.size(); ++k) {
      if (data.size() - at < 8) {
        if (partial) return;
        Fail(
            fmt::format("{}: an element tag is cut off by the end of the array: the file is "
                        "corrupt",
                        Variable()));
      }
      const Element e = ReadTag(data.substr(at));
      // What the element claims must fit in what its array claims, even
      // where only the start of a compressed array was inflated.
      // (A small element's data lies inside its 8-byte tag.)
      const std::uint64_t room = nbytes > at + 8 ? nbytes - at - 8 : 0;
      if ((!e.small && e.nbytes > room) || (e.small && at + 8 > nbytes) ||
          (e.data.size() < e.nbytes && !(partial && data.size() < nbytes))) {
        Fail(
            fmt::format("{}: an element claims {} bytes, more than the {} bytes left in its "
                        "array: the file is corrupt",
                        Variable(), e.nbytes, room));
      }
      if (e.data.size() < e.nbytes) return;  // the rest was not inflated
      if (k == 0 && (e.small || (e.type != kMiUint32 && e.type != kMiInt32) || e.nbytes != 8)) {
        // matio reads the array flags as 8 bytes after their tag whatever the
        // tag claims, and the dimensions right after: another size would put
        // it on other bytes than this check (flags claiming 50 bytes hid a
        // dimensions tag of type 10 before a 1.8 GB name: 11 s).
        Fail(
            fmt::format("{}: its array flags element has type {} and {} bytes, not miUINT32 (6) "
                        "and 8 bytes: the file is corrupt",
                        Variable(), e.type, e.nbytes));
      } else if (k == 0) {
        cls = U32(e.data, 0) & 0xFF;
        if (depth == 0) {
          top_.array_class = cls;
          top_.complex = (U32(e.data, 0) & 0x0800) != 0;
        }
      } else if (k == 1 && e.type != kMiInt32) {
        // matio reads the dimensions as int32 whatever the tag says, so a
        // mistyped tag would reach it unchecked (10 "dimensions" from 50
        // bytes of text made it allocate 1.8 GB).
        Fail(
            fmt::format("{}: its dimensions element has type {}, not miINT32 (5): the file is "
                        "corrupt",
                        Variable(), e.type));
      } else if (k == 1 && e.small) {
        // Dimensions take at least 8 bytes (two int32), so never the small
        // format; matio reads its data word as the byte count (4 bytes of
        // data 0x26000000 made it ask for 2.5 GB).
        Fail(
            fmt::format("{}: its dimensions element is in the small data element format ({} "
                        "bytes), too short for two dimensions: the file is corrupt",
                        Variable(), e.nbytes));
      } else if (k == 1 && (e.nbytes % 4 != 0 || e.nbytes < 8)) {
        // matio reads nbytes / 4 dimensions (and one more word for an odd
        // count), so other sizes put its next read elsewhere than this check.
        Fail(
            fmt::format("{}: its dimensions element holds {} bytes, not two or more int32: the "
                        "file is corrupt",
                        Variable(), e.nbytes));
      } else if (k == 1) {
        for (std::size_t d = 0; d + 4 <= e.data.size(); d += 4) {
          const auto n = static_cast<std::int32_t>(U32(e.data, d));
          if (n < 0)
            Fail(fmt::format("{}: negative dimension {}: the file is corrupt", Variable(), n));
          elements *= static_cast<double>(n);
          dims += (d == 0 ? "" : "x") + std::to_string(n);
          if (depth == 0) top_.dims.push_back(static_cast<std::size_t>(n));
        }
      } else if (k == 2 && e.type != kMiInt8) {
        // matio skips only the tag of a name of another type and reads on
        // from its data.
        Fail(fmt::format("{}: its name element has type {}, not miINT8 (1): the file is corrupt",
                         Variable(), e.type));
      } else if (k == 2 && depth == 0) {
        name_ = Excerpt(e.data);
        top_.name = std::string(e.data.substr(0, e.data.find('\0')));
      } else if (k == 3 && cls == kClassStruct &&
                 (!e.small || e.type != kMiInt32 || e.nbytes != 4)) {
        // matio takes the word after the tag as the length, which only the
        // small format (the length inside the tag) puts there.
        Fail(
            fmt::format("{}: its field name length is not a 4-byte miINT32 in the small data "
                        "element format (type {}, {} bytes): the file is corrupt",
                        Variable(), e.type, e.nbytes));
      } else if (k == 3 && cls == kClassStruct) {
        field_name_length = U32(e.data, 0);
      } else if (k == 4 && cls == kClassStruct &&
                 (e.type != kMiInt8 ||
                  (field_name_length != 0 && e.nbytes % field_name_length != 0))) {
        Fail(
            fmt::format("{}: its field names element (type {}, {} bytes) is not miINT8 names "
                        "of {} bytes each: the file is corrupt",
                        Variable(), e.type, e.nbytes, field_name_length));
      } else if (k == 4 && cls == kClassStruct) {
        fields = field_name_length == 0 ? 0.0 : static_cast<double>(e.nbytes / field_name_length);
      }
      if ((k == 2 && cls != kClassStruct) || (k == 4 && cls == kClassStruct)) {
        CheckElementCount(cls, elements * fields, dims, nbytes);
      }
      // The contents of a cell array or a struct are arrays; matio fails on
      // another element there and leaks the contents it has read.
      if (((cls == kClassCell && k >= 3) || (cls == kClassStruct && k >= 5)) &&
          e.type != kMiMatrix) {
        Fail(
            fmt::format("{}: element {} of its {} contents has type {}, not miMATRIX (14): the "
                        "file is corrupt",
                        Variable(), k - (cls == kClassCell ? 2 : 4),
                        cls == kClassCell ? "cell" : "struct", e.type));
      }
      if (k >= 3 && e.type == kMiMatrix) CheckMatrix(e.data, e.nbytes, partial, depth + 1);
      at += e.size_on_disk;
    }
  }

  /// Every element of an array takes at least one byte (numeric, char,
  /// logical) or one 8-byte tag (cell, struct field).
  void CheckElementCount(std::uint32_t cls, double elements, const std::string& dims,
                         std::uint64_t nbytes) const {
    // Sparse, object and opaque arrays store sizes not tied to the
    // dimensions. Function handles are checked like numeric arrays: matio
    // allocates their dimensions' worth of doubles (a 416-byte file with a
    // 1296629765x1 function-class array made it ask for 10 GB).
    if (cls == kClassSparse || cls == kClassObject || cls == kClassOpaque) return;
    const double min_bytes = (cls == kClassCell || cls == kClassStruct ? 8.0 : 1.0) * elements;
    if (min_bytes > static_cast<double>(nbytes)) {
      Fail(
          fmt::format("{} claims dimensions {} ({} elements) but holds only {} bytes: the file "
                      "is corrupt",
                      Variable(), dims, elements, nbytes));
    }
  }

  const std::string& path_;
  bool swap_;
  int index_ = 0;
  std::string name_;
  MatScanVariable top_;  ///< the top-level variable being checked
};

/// MAT v4 (MAT-File Format, ch. 1, "Level 4 MAT-files"): a sequence of
/// variables, each a 20-byte header (type MOPT, rows, columns, imaginary flag,
/// name length), the name and the data. Headers that do not look like v4 end
/// the check (matio then decides); sizes beyond the file are errors.
void ScanMatV4(const std::string& path, std::string_view bytes) {
  std::size_t offset = 0;
  for (int index = 1; offset < bytes.size(); ++index) {
    const std::string_view rest = bytes.substr(offset);
    if (rest.size() < 20) {
      if (index == 1) return;  // too short for v4: matio decides
      throw DataError(
          fmt::format("{}: the file ends inside the header of variable {} ({} bytes "
                      "left): the file is truncated (or not a MAT file)",
                      path, index, rest.size()));
    }
    std::int32_t h[5];
    std::memcpy(h, rest.data(), sizeof(h));
    // The type MOPT is read in whichever byte order makes it valid; the other
    // fields, as matio reads them, in the byte order its M digit declares
    // (0: little-endian, 1: big-endian), whatever order the type was stored
    // in. They must then be sane, or matio would allocate what they claim (a
    // big-endian header whose type declares little-endian data, M = 0, made
    // it allocate its name length unswapped: 2 GB).
    auto valid_type = [](std::int32_t t) {
      return t >= 0 && t <= 4052 && (t / 100) % 10 == 0 && (t / 10) % 10 <= 5 && t % 10 <= 2;
    };
    auto swap = [](std::int32_t v) {
      return static_cast<std::int32_t>(__builtin_bswap32(static_cast<std::uint32_t>(v)));
    };
    if (!valid_type(h[0])) h[0] = swap(h[0]);
    if (!valid_type(h[0])) {
      if (index == 1) return;  // not v4: matio decides
      throw DataError(
          fmt::format("{}: variable {} at offset {}: invalid header (type {}): the "
                      "file is corrupt",
                      path, index, offset, h[0]));
    }
    const int machine = h[0] / 1000;  // 0 IEEE little-endian, 1 IEEE big-endian, 2-4 VAX, Cray
    if (machine > 1) {
      throw DataError(
          fmt::format("{}: variable {} at offset {}: type {} declares a VAX or Cray number "
                      "format (M = {}), which is not read; save the data as IEEE (MATLAB -v4 on "
                      "any current machine)",
                      path, index, offset, h[0], machine));
    }
    if ((machine == 1) == (std::endian::native == std::endian::little)) {
      for (int i = 1; i < 5; ++i) h[i] = swap(h[i]);
    }
    if (h[1] < 0 || h[2] < 0 || (h[3] != 0 && h[3] != 1) || h[4] < 0) {
      throw DataError(
          fmt::format("{}: variable {} at offset {}: invalid header (rows {}, columns "
                      "{}, imaginary flag {}, name length {}): the file is corrupt",
                      path, index, offset, h[1], h[2], h[3], h[4]));
    }
    static constexpr double kPrecisionBytes[] = {8, 4, 4, 2, 2, 1};
    const double data = static_cast<double>(h[1]) * static_cast<double>(h[2]) *
                        kPrecisionBytes[(h[0] / 10) % 10] * (h[3] == 1 ? 2.0 : 1.0);
    const double need = 20.0 + static_cast<double>(h[4]) + data;
    if (need > static_cast<double>(rest.size())) {
      const std::size_t name_length =
          std::min<std::size_t>(static_cast<std::size_t>(h[4]), rest.size() - 20);
      std::string_view name = rest.substr(20, name_length);
      name = name.substr(0, name.find('\0'));
      throw DataError(fmt::format(
          "{}: variable {} ('{}') claims {}x{} elements, {} bytes from offset {}, but the file "
          "has {} bytes left: the file is truncated or corrupt",
          path, index, Excerpt(name), h[1], h[2], need, offset, rest.size()));
    }
    offset += static_cast<std::size_t>(need);
  }
}

}  // namespace

MatScan ScanMatFile(const std::string& path, std::string_view bytes) {
  if (bytes.size() < 128 || (bytes.substr(126, 2) != "IM" && bytes.substr(126, 2) != "MI")) {
    ScanMatV4(path, bytes);
    return {};
  }
  const std::string_view endian = bytes.substr(126, 2);
  const bool swap = endian == "MI";
  std::uint16_t version = 0;
  std::memcpy(&version, bytes.data() + 124, 2);
  if (swap) version = __builtin_bswap16(version);
  if (version == 0x0200) return {};  // v7.3 (HDF5): the HDF5 library checks its own sizes
  if (version != 0x0100) {
    // matio reads a header with another version as v4: check it as v4 too.
    ScanMatV4(path, bytes);
    return {};
  }
  return Scanner(path, swap).ScanFile(bytes);
}

}  // namespace pneumid::internal
