#include "pneumid/data/matfile.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <matio.h>

#include "column_spec.hpp"
#include "mapped_file.hpp"
#include "mat_scan.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {
namespace {

// matio reports problems through a log function; keep the last message so that
// errors can quote it, and keep matio from printing on stderr.
thread_local std::string g_matio_message;

void MatioLog(int /*level*/, char* message) { g_matio_message = message == nullptr ? "" : message; }

void InstallMatioLogger() {
  static std::once_flag once;
  std::call_once(once, [] { Mat_LogInitFunc("pneumid", &MatioLog); });
}

std::string MatioDetail() {
  if (g_matio_message.empty()) return "";
  return fmt::format(" (matio: {})", g_matio_message);
}

struct MatCloser {
  void operator()(mat_t* m) const {
    if (m != nullptr) Mat_Close(m);
  }
};
struct VarFreer {
  void operator()(matvar_t* v) const {
    if (v != nullptr) Mat_VarFree(v);
  }
};
using MatPtr = std::unique_ptr<mat_t, MatCloser>;
using VarPtr = std::unique_ptr<matvar_t, VarFreer>;

bool IsNumericClass(matio_classes c) {
  switch (c) {
    case MAT_C_DOUBLE:
    case MAT_C_SINGLE:
    case MAT_C_INT8:
    case MAT_C_UINT8:
    case MAT_C_INT16:
    case MAT_C_UINT16:
    case MAT_C_INT32:
    case MAT_C_UINT32:
    case MAT_C_INT64:
    case MAT_C_UINT64:
      return true;
    default:
      return false;
  }
}

std::size_t ElementSize(matio_classes c) {
  switch (c) {
    case MAT_C_INT8:
    case MAT_C_UINT8:
      return 1;
    case MAT_C_INT16:
    case MAT_C_UINT16:
      return 2;
    case MAT_C_INT32:
    case MAT_C_UINT32:
    case MAT_C_SINGLE:
      return 4;
    default:
      return 8;
  }
}

std::string ClassName(matio_classes c) {
  switch (c) {
    case MAT_C_CELL:
      return "cell";
    case MAT_C_STRUCT:
      return "struct";
    case MAT_C_OBJECT:
      return "object";
    case MAT_C_CHAR:
      return "char";
    case MAT_C_SPARSE:
      return "sparse";
    case MAT_C_DOUBLE:
      return "double";
    case MAT_C_SINGLE:
      return "single";
    case MAT_C_FUNCTION:
      return "function handle";
    case MAT_C_OPAQUE:
      return "opaque";
    case MAT_C_EMPTY:
      return "unknown class";
    default:
      return "integer";
  }
}

/// Description of one variable of the file.
struct VarInfo {
  std::string name;
  std::string label;  ///< the name as quoted in messages (a short excerpt)
  matio_classes class_type = MAT_C_EMPTY;
  bool complex = false;
  std::vector<std::size_t> dims;

  bool numeric() const { return IsNumericClass(class_type) && !complex && dims.size() == 2; }
  std::size_t rows() const {
    if (dims.size() != 2) return 0;
    return (dims[0] == 1) ? dims[1] : dims[0];
  }
  std::size_t cols() const {
    if (dims.size() != 2) return 0;
    return (dims[0] == 1) ? 1 : dims[1];
  }
  std::string shape() const {
    std::string s;
    for (std::size_t i = 0; i < dims.size(); ++i) s += (i ? "x" : "") + std::to_string(dims[i]);
    return s;
  }
};

/// Channels one variable may give when it is selected whole.
constexpr std::size_t kMaxChannelsPerVariable = 1000;

template <typename T>
void CopyAs(const void* data, std::size_t n, Eigen::MatrixXd& out) {
  const T* p = static_cast<const T*>(data);
  for (std::size_t i = 0; i < n; ++i) out.data()[i] = static_cast<double>(p[i]);
}

/// Whether matio is given a top-level element of a v5 file: numeric arrays
/// only. pneumid reads nothing else, and matio's readers of cell arrays,
/// structs, objects and function handles fail on corrupt contents without
/// freeing what they have read (each found by fuzzing), so they never reach it.
/// The matio class of a scanned variable; MAT_C_EMPTY for a class number
/// beyond the format's 17 (not a value of matio's enum).
matio_classes ClassOf(const internal::MatScanVariable& v) {
  return v.array_class <= MAT_C_OPAQUE ? static_cast<matio_classes>(v.array_class) : MAT_C_EMPTY;
}

bool Readable(const internal::MatScanVariable& v) { return IsNumericClass(ClassOf(v)); }

/// Writes the header and the numeric variables of the v5 file `bytes` to a
/// new temporary file and returns its path.
std::string WriteNumericCopy(std::string_view bytes, const internal::MatScan& scan) {
  std::string path = (std::filesystem::temp_directory_path() / "pneumid-mat-XXXXXX").string();
  const int fd = ::mkstemp(path.data());
  if (fd < 0) throw DataError(fmt::format("cannot create a temporary file {}", path));
  std::string out(bytes.substr(0, 128));
  for (const auto& v : scan.variables) {
    if (Readable(v)) out += bytes.substr(v.offset, v.size);
  }
  std::size_t done = 0;
  while (done < out.size()) {
    const ssize_t n = ::write(fd, out.data() + done, out.size() - done);
    if (n <= 0) {
      ::close(fd);
      ::unlink(path.c_str());
      throw DataError(fmt::format("cannot write the temporary file {}", path));
    }
    done += static_cast<std::size_t>(n);
  }
  ::close(fd);
  return path;
}

class MatReader {
 public:
  explicit MatReader(const std::string& path) : path_(path) {
    InstallMatioLogger();
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) {
      throw DataError(fmt::format("{}: cannot open: no such file", path));
    }
    if (S_ISDIR(st.st_mode)) throw DataError(fmt::format("{}: is a directory", path));
    if (st.st_size == 0) throw DataError(fmt::format("{}: empty file (not a MAT file)", path));
    file_size_ = static_cast<std::size_t>(st.st_size);
    internal::MatScan scan;
    std::string copy;  // a copy of the file without its non-numeric variables
    {
      // Sizes claimed by the file are checked before matio trusts them.
      const internal::MappedFile file(path);
      scan = internal::ScanMatFile(path, file.view());
      if (std::any_of(scan.variables.begin(), scan.variables.end(),
                      [](const auto& v) { return !Readable(v); })) {
        copy = WriteNumericCopy(file.view(), scan);
      }
    }
    g_matio_message.clear();
    mat_.reset(Mat_Open(copy.empty() ? path.c_str() : copy.c_str(), MAT_ACC_RDONLY));
    if (!copy.empty()) ::unlink(copy.c_str());  // matio holds it open
    if (!mat_) {
      throw DataError(fmt::format("{}: cannot open as a MAT file (v4, v5{}){}", path,
                                  MatHasV73() ? " or v7.3" : "; v7.3 needs matio with HDF5",
                                  MatioDetail()));
    }
    std::vector<VarInfo> listed;
    while (true) {
      VarPtr v(Mat_VarReadNextInfo(mat_.get()));
      if (!v) break;
      VarInfo info;
      info.name = v->name == nullptr ? "" : v->name;
      info.label = Excerpt(info.name);
      info.class_type = v->class_type;
      info.complex = v->isComplex != 0;
      for (int d = 0; d < v->rank; ++d) info.dims.push_back(v->dims[d]);
      listed.push_back(std::move(info));
    }
    Mat_Rewind(mat_.get());
    if (copy.empty()) {
      vars_ = std::move(listed);
      return;
    }
    // The variables left out of the copy are listed, in file order, as the
    // scan read them, so that selecting one says what it is.
    std::size_t next = 0;
    for (const auto& v : scan.variables) {
      if (Readable(v)) {
        if (next < listed.size()) vars_.push_back(std::move(listed[next++]));
      } else if (v.array_class != 0) {
        VarInfo info;
        info.name = v.name;
        info.label = Excerpt(v.name);
        info.class_type = ClassOf(v);
        info.complex = v.complex;
        info.dims = v.dims;
        vars_.push_back(std::move(info));
      }
    }
    for (; next < listed.size(); ++next) vars_.push_back(std::move(listed[next]));
  }

  /// Columns selected by `spec`, with their channel names.
  void Select(const std::string& spec, const std::string& role, std::vector<Eigen::VectorXd>* cols,
              std::vector<Channel>* channels) {
    if (const VarInfo* v = Find(spec)) {
      // Each column becomes a channel; more than any experiment logs is a
      // corrupt header or a matrix stored with its samples along the rows.
      if (v->numeric() && v->rows() > 0 && v->cols() > kMaxChannelsPerVariable) {
        throw DataError(fmt::format(
            "{}: {} variable '{}' ({} {}) would give {} channels, more than {}: store samples "
            "along the rows (N x k), or select one column with '{}:K'",
            path_, role, v->label, v->shape(), ClassName(v->class_type), v->cols(),
            kMaxChannelsPerVariable, v->label));
      }
      const Eigen::MatrixXd& m = Read(*v, role);
      for (Eigen::Index c = 0; c < m.cols(); ++c) {
        cols->push_back(m.col(c));
        channels->push_back({m.cols() == 1 ? v->name : fmt::format("{}:{}", v->name, c), ""});
      }
      return;
    }
    const auto colon = spec.rfind(':');
    std::size_t index = 0;
    if (colon != std::string::npos && internal::IsIndex(spec.substr(colon + 1), &index)) {
      if (const VarInfo* v = Find(spec.substr(0, colon))) {
        TakeColumn(*v, index, role, cols, channels);
        return;
      }
    }
    if (internal::IsIndex(spec, &index)) {
      std::vector<const VarInfo*> numeric;
      for (const auto& v : vars_) {
        if (v.numeric()) numeric.push_back(&v);
      }
      if (numeric.size() == 1) {
        TakeColumn(*numeric[0], index, role, cols, channels);
        return;
      }
      throw DataError(fmt::format(
          "{}: {} column index '{}' needs a file with exactly one numeric matrix variable, this "
          "one has {}; select 'name:{}' instead (variables: {})",
          path_, role, Excerpt(spec), numeric.size(), index, ListVariables()));
    }
    throw DataError(fmt::format("{}: unknown {} variable '{}'; available variables: {}", path_,
                                role, Excerpt(spec), ListVariables()));
  }

  const std::string& path() const { return path_; }

 private:
  const VarInfo* Find(const std::string& name) const {
    for (const auto& v : vars_) {
      if (v.name == name) return &v;
    }
    return nullptr;
  }

  std::string ListVariables() const {
    if (vars_.empty()) return "(none)";
    std::string out;
    const std::size_t shown = std::min(vars_.size(), internal::kMaxListedColumns);
    for (std::size_t i = 0; i < shown; ++i) {
      const auto& v = vars_[i];
      out += fmt::format("{}'{}' ({} {}{})", i ? ", " : "", v.label, v.shape(),
                         v.complex ? "complex " : "", ClassName(v.class_type));
    }
    if (shown < vars_.size()) out += fmt::format(", ... ({} variables in all)", vars_.size());
    return out;
  }

  void TakeColumn(const VarInfo& v, std::size_t index, const std::string& role,
                  std::vector<Eigen::VectorXd>* cols, std::vector<Channel>* channels) {
    const Eigen::MatrixXd& m = Read(v, role);
    if (index >= static_cast<std::size_t>(m.cols())) {
      throw DataError(
          fmt::format("{}: variable '{}': {} column {} out of range: it is {} ({} "
                      "columns)",
                      path_, v.label, role, index, v.shape(), m.cols()));
    }
    cols->push_back(m.col(static_cast<Eigen::Index>(index)));
    channels->push_back({fmt::format("{}:{}", v.name, index), ""});
  }

  const Eigen::MatrixXd& Read(const VarInfo& v, const std::string& role) {
    auto it = cache_.find(v.name);
    if (it != cache_.end()) return it->second;
    // matio reads a variable by name, i.e. the first one of that name: a file
    // that repeats a name (no MATLAB save does) cannot say which one is meant,
    // and the size checked below would be another variable's.
    std::vector<std::size_t> same;
    for (std::size_t i = 0; i < vars_.size(); ++i) {
      if (vars_[i].name == v.name) same.push_back(i + 1);
    }
    if (same.size() > 1) {
      throw DataError(fmt::format(
          "{}: variable name '{}' appears {} times in the file (variables {}): it cannot say "
          "which one is the {} data; the file is corrupt or was not written by a MAT writer",
          path_, v.label, same.size(), fmt::join(same, ", "), role));
    }
    if (!IsNumericClass(v.class_type) || v.complex) {
      throw DataError(fmt::format("{}: variable '{}' ({}): {} data must be a real numeric array",
                                  path_, v.label,
                                  (v.complex ? "complex " : "") + ClassName(v.class_type), role));
    }
    if (v.dims.size() != 2) {
      throw DataError(
          fmt::format("{}: variable '{}' is {}-dimensional ({}); expected a vector or "
                      "an N x k matrix",
                      path_, v.label, v.dims.size(), v.shape()));
    }
    // An empty variable holds no samples, whatever its other dimension claims
    // (a 22-byte v4 file claiming 0 x 5e6 made a channel per column: 2 GB).
    if (v.dims[0] == 0 || v.dims[1] == 0) {
      throw DataError(fmt::format("{}: variable '{}' is empty ({} {}): it holds no {} samples",
                                  path_, v.label, v.shape(), ClassName(v.class_type), role));
    }
    // A corrupt header can claim any size; zlib expands at most ~1032:1, so a
    // variable cannot hold more than about 1100 bytes per byte of file.
    const double claimed = static_cast<double>(v.dims[0]) * static_cast<double>(v.dims[1]) *
                           static_cast<double>(ElementSize(v.class_type));
    const double limit = 1100.0 * static_cast<double>(file_size_) + 1e6;
    if (claimed > limit) {
      throw DataError(
          fmt::format("{}: variable '{}' claims {} elements ({}), more than the file "
                      "can hold: the file is corrupt",
                      path_, v.label, v.shape(), ClassName(v.class_type)));
    }
    Mat_Rewind(mat_.get());
    g_matio_message.clear();
    VarPtr var(Mat_VarRead(mat_.get(), v.name.c_str()));
    if (!var || var->data == nullptr) {
      throw DataError(
          fmt::format("{}: variable '{}': cannot read its data{}", path_, v.label, MatioDetail()));
    }
    const std::size_t rows = var->dims[0];
    const std::size_t cols = var->dims[1];
    const std::size_t n = rows * cols;
    Eigen::MatrixXd m(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
    switch (var->class_type) {
      case MAT_C_DOUBLE:
        CopyAs<double>(var->data, n, m);
        break;
      case MAT_C_SINGLE:
        CopyAs<float>(var->data, n, m);
        break;
      case MAT_C_INT8:
        CopyAs<std::int8_t>(var->data, n, m);
        break;
      case MAT_C_UINT8:
        CopyAs<std::uint8_t>(var->data, n, m);
        break;
      case MAT_C_INT16:
        CopyAs<std::int16_t>(var->data, n, m);
        break;
      case MAT_C_UINT16:
        CopyAs<std::uint16_t>(var->data, n, m);
        break;
      case MAT_C_INT32:
        CopyAs<std::int32_t>(var->data, n, m);
        break;
      case MAT_C_UINT32:
        CopyAs<std::uint32_t>(var->data, n, m);
        break;
      case MAT_C_INT64:
        CopyAs<std::int64_t>(var->data, n, m);
        break;
      case MAT_C_UINT64:
        CopyAs<std::uint64_t>(var->data, n, m);
        break;
      default:
        throw DataError(fmt::format("{}: variable '{}': unsupported class", path_, v.label));
    }
    if (rows == 1) m.transposeInPlace();  // a row vector is one channel
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      for (Eigen::Index r = 0; r < m.rows(); ++r) {
        if (!std::isfinite(m(r, c))) {
          throw DataError(fmt::format(
              "{}: variable '{}' element ({}, {}) (sample {}, column {}): {} value", path_, v.label,
              r + 1, c + 1, r, c, std::isnan(m(r, c)) ? "NaN" : "infinite"));
        }
      }
    }
    return cache_.emplace(v.name, std::move(m)).first->second;
  }

  std::string path_;
  std::size_t file_size_ = 0;
  MatPtr mat_;
  std::vector<VarInfo> vars_;
  std::map<std::string, Eigen::MatrixXd> cache_;
};

}  // namespace

namespace {
constexpr EnumName<MatVersion> kMatVersionNames[] = {
    {MatVersion::kV5, "v5"},
    {MatVersion::kV73, "v7.3"},
    {MatVersion::kV5, "5"},
    {MatVersion::kV73, "7.3"},
    {MatVersion::kV73, "v73"},
};
}  // namespace

std::string ToString(MatVersion v) { return std::string(EnumToString(kMatVersionNames, v)); }

MatVersion MatVersionFromString(const std::string& name) {
  return EnumFromString(kMatVersionNames, name, "MAT file version");
}

bool MatHasV73() {
  static const bool has = [] {
    InstallMatioLogger();
    char dir_template[] = "/tmp/pneumid-matio-XXXXXX";
    const char* dir = ::mkdtemp(dir_template);
    if (dir == nullptr) return false;
    const std::string file = std::string(dir) + "/probe.mat";
    mat_t* m = Mat_CreateVer(file.c_str(), nullptr, MAT_FT_MAT73);
    const bool ok = m != nullptr;
    if (m != nullptr) Mat_Close(m);
    std::remove(file.c_str());
    ::rmdir(dir);
    return ok;
  }();
  return has;
}

bool MatReadOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string message) {
    if (error != nullptr) *error = std::move(message);
    return false;
  };
  if (!std::isfinite(sample_time) || sample_time < 0) {
    return fail(fmt::format("MatReadOptions: sample_time must be >= 0, got {}", sample_time));
  }
  if (!std::isfinite(start_time)) {
    return fail(fmt::format("MatReadOptions: start_time must be finite, got {}", start_time));
  }
  if (sample_time == 0 && time_variable.empty()) {
    return fail("MatReadOptions: give a time variable or a sample time > 0");
  }
  if (input_variables.empty() && output_variables.empty()) {
    return fail("MatReadOptions: select at least one input or output variable");
  }
  for (const auto& v : input_variables) {
    if (v.empty()) return fail("MatReadOptions: empty input variable name");
  }
  for (const auto& v : output_variables) {
    if (v.empty()) return fail("MatReadOptions: empty output variable name");
  }
  return true;
}

Dataset ReadMat(const std::string& path, const MatReadOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "ReadMat: {}", error);
  MatReader reader(path);

  std::vector<Eigen::VectorXd> time_cols, in_cols, out_cols;
  std::vector<Channel> time_ch, in_ch, out_ch;
  const bool has_time = options.sample_time <= 0;
  if (has_time) {
    reader.Select(options.time_variable, "time", &time_cols, &time_ch);
    if (time_cols.size() != 1) {
      throw DataError(fmt::format("{}: time variable '{}' has {} columns; select one with '{}:0'",
                                  path, options.time_variable, time_cols.size(),
                                  options.time_variable));
    }
  }
  for (const auto& s : options.input_variables) reader.Select(s, "input", &in_cols, &in_ch);
  for (const auto& s : options.output_variables) reader.Select(s, "output", &out_cols, &out_ch);

  Eigen::Index n = -1;
  std::string first_name;
  auto check_length = [&](const std::vector<Eigen::VectorXd>& cols,
                          const std::vector<Channel>& chans) {
    for (std::size_t i = 0; i < cols.size(); ++i) {
      if (n < 0) {
        n = cols[i].size();
        first_name = chans[i].name;
      } else if (cols[i].size() != n) {
        throw DataError(
            fmt::format("{}: variable '{}' has {} samples but '{}' has {} (length "
                        "mismatch)",
                        path, chans[i].name, cols[i].size(), first_name, n));
      }
    }
  };
  check_length(time_cols, time_ch);
  check_length(in_cols, in_ch);
  check_length(out_cols, out_ch);
  if (n <= 0) throw DataError(fmt::format("{}: variable '{}' has no samples", path, first_name));

  Eigen::VectorXd time(n);
  if (has_time) {
    time = time_cols[0];
    for (Eigen::Index i = 1; i < n; ++i) {
      if (!(time[i] > time[i - 1])) {
        throw DataError(fmt::format(
            "{}: variable '{}' sample {}: time is not strictly increasing: t = {} after t = {}",
            path, time_ch[0].name, i, time[i], time[i - 1]));
      }
    }
  } else {
    for (Eigen::Index i = 0; i < n; ++i) {
      time[i] = options.start_time + static_cast<double>(i) * options.sample_time;
    }
  }
  auto stack = [&](const std::vector<Eigen::VectorXd>& cols) {
    Eigen::MatrixXd m(n, static_cast<Eigen::Index>(cols.size()));
    for (std::size_t c = 0; c < cols.size(); ++c) m.col(static_cast<Eigen::Index>(c)) = cols[c];
    return m;
  };
  Dataset data(std::move(time), stack(in_cols), stack(out_cols), std::move(in_ch),
               std::move(out_ch));
  if (has_time) data.set_time_channel({time_ch[0].name, "s"});
  data.set_source(path);
  return data;
}

bool MatWriteOptions::IsValid(std::string* error) const {
  auto valid_name = [](const std::string& s) {
    if (s.empty() || s.size() > 63) return false;
    if (!std::isalpha(static_cast<unsigned char>(s[0]))) return false;
    for (char c : s) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
    }
    return true;
  };
  for (const auto* s : {&time_variable, &input_variable, &output_variable}) {
    if (!valid_name(*s)) {
      if (error != nullptr) {
        *error = fmt::format("MatWriteOptions: '{}' is not a valid MATLAB variable name", *s);
      }
      return false;
    }
  }
  if (time_variable == input_variable || time_variable == output_variable ||
      input_variable == output_variable) {
    if (error != nullptr) *error = "MatWriteOptions: variable names must differ";
    return false;
  }
  return true;
}

void WriteMat(const Dataset& data, const std::string& path, const MatWriteOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "WriteMat: {}", error);
  InstallMatioLogger();
  if (options.version == MatVersion::kV73 && !MatHasV73()) {
    throw DataError(
        fmt::format("{}: cannot write MAT v7.3: this matio build has no HDF5 support; "
                    "write v5 instead",
                    path));
  }
  g_matio_message.clear();
  std::remove(path.c_str());  // matio refuses to overwrite some existing files
  MatPtr mat(Mat_CreateVer(path.c_str(), nullptr,
                           options.version == MatVersion::kV5 ? MAT_FT_MAT5 : MAT_FT_MAT73));
  if (!mat) {
    throw DataError(fmt::format("{}: cannot create MAT file{}", path, MatioDetail()));
  }
  const matio_compression compression =
      options.compress ? MAT_COMPRESSION_ZLIB : MAT_COMPRESSION_NONE;
  auto write = [&](const std::string& name, const Eigen::MatrixXd& m) {
    if (m.cols() == 0) return;
    std::size_t dims[2] = {static_cast<std::size_t>(m.rows()), static_cast<std::size_t>(m.cols())};
    VarPtr var(Mat_VarCreate(name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                             const_cast<double*>(m.data()), MAT_F_DONT_COPY_DATA));
    if (!var || Mat_VarWrite(mat.get(), var.get(), compression) != 0) {
      throw DataError(fmt::format("{}: cannot write variable '{}'{}", path, name, MatioDetail()));
    }
  };
  write(options.time_variable, data.time());
  write(options.input_variable, data.inputs());
  write(options.output_variable, data.outputs());
  if (Mat_Close(mat.release()) != 0) {
    throw DataError(fmt::format("{}: cannot close MAT file{}", path, MatioDetail()));
  }
}

}  // namespace pneumid
