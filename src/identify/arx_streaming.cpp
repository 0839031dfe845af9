#include "pneumid/identify/arx_streaming.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string_view>
#include <vector>

#include "pneumid/common/check.hpp"

namespace pneumid {

bool StreamingArxOptions::IsValid(std::string* error) const {
  if (!arx.IsValid(error)) return false;
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (arx.nb.size() != 1) return fail("streaming ARX is single-input (one nb, one nk)");
  if (sample_time < 0) return fail(fmt::format("sample_time must be >= 0, got {}", sample_time));
  if (chunk_bytes < 4096)
    return fail(fmt::format("chunk_bytes must be >= 4096, got {}", chunk_bytes));
  if (input_column.empty() || output_column.empty()) return fail("column names must not be empty");
  return true;
}

namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

std::vector<std::string_view> Split(std::string_view line, char delim) {
  std::vector<std::string_view> out;
  if (delim == ' ') {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i >= line.size()) break;
      std::size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
      out.push_back(line.substr(i, j - i));
      i = j;
    }
    return out;
  }
  std::size_t start = 0;
  for (std::size_t i = 0; i <= line.size(); ++i) {
    if (i == line.size() || line[i] == delim) {
      out.push_back(line.substr(start, i - start));
      start = i + 1;
    }
  }
  return out;
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '"'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '"'))
    s.remove_suffix(1);
  return s;
}

bool ParseDouble(std::string_view s, double* v) {
  s = Trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && !s.empty();
}

int ResolveColumn(const std::string& spec, const std::vector<std::string>& header,
                  std::size_t num_fields, const std::string& path, const char* role) {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == spec) return static_cast<int>(i);
  int idx = -1;
  const auto r = std::from_chars(spec.data(), spec.data() + spec.size(), idx);
  if (r.ec == std::errc() && r.ptr == spec.data() + spec.size() && idx >= 0 &&
      static_cast<std::size_t>(idx) < num_fields)
    return idx;
  std::string names;
  for (const auto& h : header) names += (names.empty() ? "" : ", ") + h;
  throw DataError(fmt::format("{}:1: {} column '{}' not found (columns: {})", path, role, spec,
                              names.empty() ? fmt::format("{} unnamed", num_fields) : names));
}

}  // namespace

StreamingArxResult EstimateArxFromFile(const std::string& path, const StreamingArxOptions& o) {
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "invalid streaming ARX options: {}", error);
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw DataError(fmt::format("{}: cannot open file", path));
  std::fseek(file.get(), 0, SEEK_END);
  const double total = static_cast<double>(std::ftell(file.get()));
  std::fseek(file.get(), 0, SEEK_SET);

  ArxAccumulator acc(o.arx);
  StreamingArxResult result;
  result.bytes = total;
  const std::size_t chunk_rows = 1 << 16;
  Eigen::VectorXd ybuf(chunk_rows), tbuf_first(2);
  Eigen::MatrixXd ubuf(chunk_rows, 1);
  std::size_t filled = 0;
  std::vector<char> buf(o.chunk_bytes);
  std::string carry;
  long long line_no = 0;
  bool have_columns = false;
  char delim = o.delimiter;
  int col_u = -1, col_y = -1, col_t = -1;
  std::size_t max_col = 0;
  double t_first[2] = {0, 0};
  long long t_count = 0;
  double bytes_read = 0;

  auto flush = [&]() {
    if (filled == 0) return;
    acc.AddSamples(ybuf.head(filled), ubuf.topRows(filled));
    filled = 0;
  };
  auto handle_line = [&](std::string_view line) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty() || line.front() == '#') return;
    if (!have_columns) {
      if (delim == '\0') {
        delim = line.find(',') != std::string_view::npos    ? ','
                : line.find(';') != std::string_view::npos  ? ';'
                : line.find('\t') != std::string_view::npos ? '\t'
                                                            : ' ';
      }
      const auto fields = Split(line, delim);
      double dummy;
      std::vector<std::string> header;
      bool numeric = true;
      for (auto f : fields) numeric = numeric && ParseDouble(f, &dummy);
      if (!numeric)
        for (auto f : fields) header.emplace_back(Trim(f));
      col_u = ResolveColumn(o.input_column, header, fields.size(), path, "input");
      col_y = ResolveColumn(o.output_column, header, fields.size(), path, "output");
      if (o.sample_time <= 0)
        col_t = ResolveColumn(o.time_column, header, fields.size(), path, "time");
      max_col = static_cast<std::size_t>(std::max({col_u, col_y, col_t}));
      have_columns = true;
      if (!numeric) return;
    }
    const auto fields = Split(line, delim);
    if (fields.size() <= max_col)
      throw DataError(fmt::format("{}:{}: {} fields, expected at least {}", path, line_no,
                                  fields.size(), max_col + 1));
    double u, y;
    if (!ParseDouble(fields[col_u], &u) || !std::isfinite(u))
      throw DataError(fmt::format("{}:{}: column '{}': not a number: '{}'", path, line_no,
                                  o.input_column, std::string(Trim(fields[col_u]))));
    if (!ParseDouble(fields[col_y], &y) || !std::isfinite(y))
      throw DataError(fmt::format("{}:{}: column '{}': not a number: '{}'", path, line_no,
                                  o.output_column, std::string(Trim(fields[col_y]))));
    if (col_t >= 0 && t_count < 2) {
      double t;
      if (!ParseDouble(fields[col_t], &t))
        throw DataError(fmt::format("{}:{}: column '{}': not a number: '{}'", path, line_no,
                                    o.time_column, std::string(Trim(fields[col_t]))));
      t_first[t_count++] = t;
    }
    ybuf[filled] = y;
    ubuf(filled, 0) = u;
    ++result.num_samples;
    if (++filled == chunk_rows) flush();
  };

  while (true) {
    const std::size_t got = std::fread(buf.data(), 1, buf.size(), file.get());
    if (got == 0) break;
    bytes_read += static_cast<double>(got);
    std::string_view view(buf.data(), got);
    std::size_t start = 0;
    for (std::size_t i = 0; i < view.size(); ++i) {
      if (view[i] != '\n') continue;
      if (!carry.empty()) {
        carry.append(view.substr(start, i - start));
        handle_line(carry);
        carry.clear();
      } else {
        handle_line(view.substr(start, i - start));
      }
      start = i + 1;
    }
    carry.append(view.substr(start));
    if (o.progress && total > 0) o.progress(bytes_read / total);
  }
  if (!carry.empty()) handle_line(carry);
  flush();
  if (!have_columns) throw DataError(fmt::format("{}: no data", path));
  double Ts = o.sample_time;
  if (Ts <= 0) {
    if (t_count < 2 || !(t_first[1] > t_first[0]))
      throw DataError(fmt::format(
          "{}: cannot determine the sample time from column '{}' (need two increasing values)",
          path, o.time_column));
    Ts = t_first[1] - t_first[0];
  }
  if (result.num_samples <= o.arx.FirstRow())
    throw DataError(fmt::format("{}: {} samples are too few for ARX", path, result.num_samples));
  result.arx = acc.Solve(Ts);
  return result;
}

}  // namespace pneumid
