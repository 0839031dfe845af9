#include "pneumid/realtime/log_writer.hpp"

#include <unistd.h>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>

#include <fmt/format.h>
#include <matio.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {
constexpr int kReservedWidth = 480;  // characters reserved for the timing / stop lines

std::string OneLine(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}
}  // namespace

namespace {
constexpr EnumName<LogFormat> kLogFormatNames[] = {
    {LogFormat::kCsv, "csv"},
    {LogFormat::kDataset, "dataset"},
    {LogFormat::kMat, "mat"},
};
}  // namespace

const char* ToString(LogFormat v) { return EnumToString(kLogFormatNames, v).data(); }

LogFormat LogFormatFromString(const std::string& name) {
  return EnumFromString(kLogFormatNames, name, "log format");
}

bool LogWriterOptions::IsValid(std::string* error) const {
  if (capacity < 16 || capacity > (std::size_t{1} << 26)) {
    if (error) *error = fmt::format("log capacity must be in [16, 2^26], got {}", capacity);
    return false;
  }
  if (!(flush_interval > 0.0 && flush_interval <= 60.0)) {
    if (error) *error = fmt::format("flush_interval must be in (0, 60] s, got {}", flush_interval);
    return false;
  }
  return true;
}

static std::size_t CheckedCapacity(const LogWriterOptions& o) {
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "invalid log options: {}", error);
  return o.capacity;
}

LogWriter::LogWriter(std::string path, std::vector<std::pair<std::string, std::string>> header,
                     LogWriterOptions options)
    : path_(std::move(path)),
      options_(options),
      header_(std::move(header)),
      ring_(CheckedCapacity(options)) {
  PNEUMID_CHECK(!path_.empty() || options_.keep_in_memory,
                "log path must not be empty (unless the log is kept in memory only)");
  if (path_.empty()) {
    mat_records_.reserve(4096);
  } else if (options_.format != LogFormat::kMat) {
    file_ = std::fopen(path_.c_str(), "w");
    if (!file_)
      throw DataError(fmt::format("{}: cannot create log file: {}", path_, std::strerror(errno)));
    std::fputs("# pneumid real-time log\n", file_);
    for (const auto& [key, value] : header_)
      std::fprintf(file_, "# %s: %s\n", OneLine(key).c_str(), OneLine(value).c_str());
    std::fputs("# timing: ", file_);
    timing_offset_ = std::ftell(file_);
    std::fprintf(file_, "%*s\n", kReservedWidth, "");
    std::fputs("# stop: ", file_);
    stop_offset_ = std::ftell(file_);
    std::fprintf(file_, "%*s\n", kReservedWidth, "");
    if (options_.format == LogFormat::kDataset)
      std::fputs("t,u,y\n", file_);
    else
      std::fputs("t,u,y,r,u_ctrl,aux,jitter_us,compute_us,flags,fault\n", file_);
    if (std::fflush(file_) != 0) {
      std::fclose(file_);
      throw DataError(fmt::format("{}: cannot write log file: {}", path_, std::strerror(errno)));
    }
  } else {
    // Check now that the file can be created, so that the run does not start for nothing.
    std::FILE* probe = std::fopen(path_.c_str(), "w");
    if (!probe)
      throw DataError(fmt::format("{}: cannot create log file: {}", path_, std::strerror(errno)));
    std::fclose(probe);
    mat_records_.reserve(4096);
  }
  thread_ = std::thread([this] { WriterMain(); });
}

LogWriter::~LogWriter() {
  if (!closed_) {
    try {
      Close();
    } catch (...) {
    }
  }
}

void LogWriter::WriteRecord(const LogRecord& r) {
  if (options_.keep_in_memory && options_.format != LogFormat::kMat) mat_records_.push_back(r);
  if (options_.format == LogFormat::kMat || !file_) {
    if (options_.format == LogFormat::kMat) mat_records_.push_back(r);
    written_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  fmt::memory_buffer buf;
  if (options_.format == LogFormat::kDataset) {
    fmt::format_to(std::back_inserter(buf), "{:.6f},{:.9g},{:.9g}\n", r.t, r.u, r.y);
  } else {
    fmt::format_to(std::back_inserter(buf),
                   "{:.6f},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.1f},{:.1f},{},{}\n", r.t, r.u, r.y,
                   r.r, r.u_ctrl, r.aux, r.jitter_us, r.compute_us, r.flags,
                   r.fault == Fault::kNone ? "" : ToString(r.fault));
  }
  if (std::fwrite(buf.data(), 1, buf.size(), file_) != buf.size()) io_error_ = true;
  written_.fetch_add(1, std::memory_order_relaxed);
}

void LogWriter::WriterMain() {
  using Clock = std::chrono::steady_clock;
  const auto interval = std::chrono::duration<double>(options_.flush_interval);
  auto last_flush = Clock::now();
  bool dirty = false;
  LogRecord r;
  for (;;) {
    const bool stopping = stop_.load(std::memory_order_acquire);
    int n = 0;
    while (ring_.TryPop(&r)) {
      WriteRecord(r);
      dirty = true;
      if (++n >= 1024) break;  // flush check between large batches
    }
    if (file_ && dirty && Clock::now() - last_flush >= interval) {
      if (std::fflush(file_) != 0) io_error_ = true;
      last_flush = Clock::now();
      dirty = false;
    }
    if (n == 0) {
      if (stopping) break;  // stop_ was set before the last (empty) drain: nothing is left
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
}

void LogWriter::WriteMat() {
  mat_t* mat = Mat_CreateVer(path_.c_str(), nullptr, MAT_FT_MAT5);
  if (!mat) throw DataError(fmt::format("{}: cannot create .mat file", path_));
  const std::size_t n = mat_records_.size();
  auto write_column = [&](const char* name, auto getter) {
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = getter(mat_records_[i]);
    std::size_t dims[2] = {n, 1};
    matvar_t* var = Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, v.data(), 0);
    const int rc = var ? Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE) : 1;
    if (var) Mat_VarFree(var);
    if (rc != 0) throw DataError(fmt::format("{}: cannot write variable '{}'", path_, name));
  };
  write_column("t", [](const LogRecord& r) { return r.t; });
  write_column("u", [](const LogRecord& r) { return r.u; });
  write_column("y", [](const LogRecord& r) { return r.y; });
  write_column("r", [](const LogRecord& r) { return r.r; });
  write_column("u_ctrl", [](const LogRecord& r) { return r.u_ctrl; });
  write_column("aux", [](const LogRecord& r) { return r.aux; });
  write_column("jitter_us", [](const LogRecord& r) { return r.jitter_us; });
  write_column("compute_us", [](const LogRecord& r) { return r.compute_us; });
  write_column("flags", [](const LogRecord& r) { return static_cast<double>(r.flags); });
  write_column("fault", [](const LogRecord& r) { return static_cast<double>(r.fault); });
  std::string text = "pneumid real-time log\n";
  for (const auto& [key, value] : header_) text += OneLine(key) + ": " + OneLine(value) + "\n";
  std::size_t dims[2] = {1, text.size()};
  matvar_t* var = Mat_VarCreate("header", MAT_C_CHAR, MAT_T_UINT8, 2, dims, text.data(), 0);
  if (var) {
    Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE);
    Mat_VarFree(var);
  }
  Mat_Close(mat);
}

void LogWriter::Close(const std::string& timing_line, const std::string& stop_line) {
  if (closed_) return;
  closed_ = true;
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  if (path_.empty()) return;
  if (options_.format == LogFormat::kMat) {
    if (!timing_line.empty()) header_.emplace_back("timing", timing_line);
    if (!stop_line.empty()) header_.emplace_back("stop", stop_line);
    WriteMat();
    return;
  }
  bool ok = !io_error_;
  auto patch = [&](long offset, const std::string& text) {
    if (offset < 0 || text.empty()) return;
    std::string t = OneLine(text).substr(0, kReservedWidth);
    if (std::fseek(file_, offset, SEEK_SET) != 0 ||
        std::fwrite(t.data(), 1, t.size(), file_) != t.size())
      ok = false;
  };
  if (std::fflush(file_) != 0) ok = false;
  patch(timing_offset_, timing_line);
  patch(stop_offset_, stop_line);
  if (std::fflush(file_) != 0) ok = false;
  ::fsync(fileno(file_));
  if (std::fclose(file_) != 0) ok = false;
  file_ = nullptr;
  if (!ok) throw DataError(fmt::format("{}: error writing the log file", path_));
}

}  // namespace pneumid
