#include "pneumid/data/csv.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string_view>

#include <fmt/format.h>

#include "column_spec.hpp"
#include "mapped_file.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"

namespace pneumid {
namespace {

inline bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

inline std::string_view StripQuotes(std::string_view s) {
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') {
    s = Trim(s.substr(1, s.size() - 2));
  }
  return s;
}

/// The content of a line without comment and surrounding blanks.
inline std::string_view LineContent(std::string_view line, char comment) {
  if (comment != '\0') {
    const void* hash = std::memchr(line.data(), comment, line.size());
    if (hash != nullptr) line = line.substr(0, static_cast<const char*>(hash) - line.data());
  }
  return Trim(line);
}

/// Number of lines in [p, end): newlines, plus one for a last line without.
Eigen::Index CountLines(const char* p, const char* end) {
  // Counted in chunks of 255 bytes into a byte counter, a loop the compiler
  // vectorizes.
  const bool unterminated = p < end && end[-1] != '\n';
  std::size_t lines = 0;
  while (end - p >= 255) {
    unsigned char chunk = 0;
    for (int i = 0; i < 255; ++i) chunk += static_cast<unsigned char>(p[i] == '\n');
    lines += chunk;
    p += 255;
  }
  for (; p < end; ++p) lines += (*p == '\n');
  return static_cast<Eigen::Index>(lines + (unterminated ? 1 : 0));
}

char DetectDelimiter(std::string_view header) {
  std::size_t best_count = 0;
  char best = ' ';
  for (char c : {',', ';', '\t'}) {
    std::size_t n = 0;
    for (char h : header) n += (h == c);
    if (n > best_count) {
      best_count = n;
      best = c;
    }
  }
  return best;
}

/// Splits `content` at the delimiter (runs of blanks when delimiter is ' ') and
/// calls f(index, cell) for every cell; returns the number of cells.
template <typename F>
inline std::size_t ForEachCell(std::string_view content, char delimiter, F&& f) {
  std::size_t index = 0;
  const char* p = content.data();
  const char* end = p + content.size();
  if (delimiter == ' ') {
    while (p < end) {
      while (p < end && IsBlank(*p)) ++p;
      if (p == end) break;
      const char* start = p;
      while (p < end && !IsBlank(*p)) ++p;
      f(index++, std::string_view(start, static_cast<std::size_t>(p - start)));
    }
    return index;
  }
  while (true) {
    const void* d = std::memchr(p, delimiter, static_cast<std::size_t>(end - p));
    const char* cell_end = d == nullptr ? end : static_cast<const char*>(d);
    f(index++, std::string_view(p, static_cast<std::size_t>(cell_end - p)));
    if (d == nullptr) break;
    p = cell_end + 1;
  }
  return index;
}

std::string DelimiterName(char d) {
  switch (d) {
    case ',':
      return "','";
    case ';':
      return "';'";
    case '\t':
      return "tab";
    case ' ':
      return "blanks";
    default:
      return fmt::format("'{}'", d);
  }
}

/// Throws DataError when `text` (the start of a file) is not 8-bit text: a
/// UTF-16/UTF-32 byte order mark, or NUL bytes (binary data or UTF-16 without
/// a byte order mark) within the first 64 KiB.
void CheckTextEncoding(const std::string& path, std::string_view text) {
  auto starts = [&](std::string_view bom) { return text.substr(0, bom.size()) == bom; };
  const char* encoding = starts(std::string_view("\xFF\xFE\0\0", 4))   ? "UTF-32LE"
                         : starts(std::string_view("\0\0\xFE\xFF", 4)) ? "UTF-32BE"
                         : starts("\xFF\xFE")                          ? "UTF-16LE"
                         : starts("\xFE\xFF")                          ? "UTF-16BE"
                                                                       : nullptr;
  if (encoding != nullptr) {
    throw DataError(fmt::format(
        "{}:1: the file is {} text (byte order mark); pneumid reads UTF-8 or ASCII: save it "
        "as UTF-8 (e.g. iconv -f {} -t UTF-8)",
        path, encoding, encoding));
  }
  const std::string_view head = text.substr(0, 64 * 1024);
  const void* nul = std::memchr(head.data(), '\0', head.size());
  if (nul != nullptr) {
    const auto offset = static_cast<std::size_t>(static_cast<const char*>(nul) - head.data());
    const long line = 1 + static_cast<long>(std::count(head.begin(), head.begin() + offset, '\n'));
    throw DataError(fmt::format(
        "{}:{}: NUL byte at offset {}: this is a binary file (or UTF-16 text without byte "
        "order mark), not delimited text; save the data as CSV in UTF-8",
        path, line, offset));
  }
}

}  // namespace

bool CsvReadOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string message) {
    if (error != nullptr) *error = std::move(message);
    return false;
  };
  if (delimiter != '\0' && delimiter != ',' && delimiter != ';' && delimiter != '\t' &&
      delimiter != ' ') {
    return fail(
        fmt::format("CsvReadOptions: delimiter must be ',', ';', tab or ' ', got '{}'", delimiter));
  }
  if (comment != '\0' && (comment == delimiter || comment == '.' || comment == '-' ||
                          comment == '+' || (comment >= '0' && comment <= '9'))) {
    return fail(fmt::format("CsvReadOptions: comment character '{}' would hide data", comment));
  }
  if (!std::isfinite(sample_time) || sample_time < 0) {
    return fail(fmt::format("CsvReadOptions: sample_time must be >= 0, got {}", sample_time));
  }
  if (!std::isfinite(start_time)) {
    return fail(fmt::format("CsvReadOptions: start_time must be finite, got {}", start_time));
  }
  if (sample_time == 0 && time_column.empty()) {
    return fail("CsvReadOptions: give a time column or a sample time > 0");
  }
  if (input_columns.empty() && output_columns.empty()) {
    return fail("CsvReadOptions: select at least one input or output column");
  }
  for (const auto& c : input_columns) {
    if (c.empty()) return fail("CsvReadOptions: empty input column name");
  }
  for (const auto& c : output_columns) {
    if (c.empty()) return fail("CsvReadOptions: empty output column name");
  }
  return true;
}

namespace {

// The reader behind ReadCsv and ReadCsvBlocks. With `on_block`, the samples are
// handed over in blocks of at most `block_rows` and not kept (*data is left
// empty); without, they are returned in *data.
Eigen::Index ReadCsvRows(const std::string& path, const CsvReadOptions& options,
                         std::size_t block_rows,
                         const std::function<void(const CsvBlock&)>* on_block, Dataset* data) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "ReadCsv: {}", error);
  internal::MappedFile file(path);
  std::string_view text = file.view();
  if (text.size() >= 3 && std::memcmp(text.data(), "\xEF\xBB\xBF", 3) == 0) {
    text.remove_prefix(3);  // UTF-8 byte order mark
  }
  CheckTextEncoding(path, text);
  if (text.empty()) throw DataError(fmt::format("{}:1: empty file (expected a header row)", path));

  const char* p = text.data();
  const char* const end = p + text.size();
  long line = 0;
  // Returns the next line (without '\n') and advances p; line counts from 1.
  auto next_line = [&]() {
    const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
    const char* line_end = nl == nullptr ? end : static_cast<const char*>(nl);
    std::string_view l(p, static_cast<std::size_t>(line_end - p));
    p = nl == nullptr ? end : line_end + 1;
    ++line;
    return l;
  };

  // Header row: the first line with content.
  std::string_view header;
  while (p < end) {
    header = LineContent(next_line(), options.comment);
    if (!header.empty()) break;
  }
  if (header.empty()) {
    throw DataError(
        fmt::format("{}:{}: empty file: no header row (only blank or comment lines)", path, line));
  }
  const long header_line = line;
  if (header.size() > kCsvMaxHeaderBytes) {
    throw DataError(fmt::format(
        "{}:{}: header row is {} bytes long (at most {}): not a header row; the file needs a "
        "first row of column names such as 't,u,y'",
        path, line, header.size(), kCsvMaxHeaderBytes));
  }
  const char delimiter = options.delimiter != '\0' ? options.delimiter : DetectDelimiter(header);
  std::vector<internal::ColumnName> columns;
  bool numeric_header = true;
  ForEachCell(header, delimiter, [&](std::size_t index, std::string_view cell) {
    if (index >= kCsvMaxColumns) return;
    cell = StripQuotes(Trim(cell));
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
    numeric_header = numeric_header && ec == std::errc() && ptr == cell.data() + cell.size();
    columns.push_back(internal::ParseColumnName(std::string(cell)));
  });
  const std::size_t header_cells = ForEachCell(header, delimiter, [](std::size_t, auto) {});
  if (header_cells > kCsvMaxColumns) {
    throw DataError(
        fmt::format("{}:{}: header row has {} columns (delimiter {}), more than the {} supported{}",
                    path, line, header_cells, DelimiterName(delimiter), kCsvMaxColumns,
                    numeric_header ? "; it holds numbers: is the header row missing?" : ""));
  }
  const std::size_t num_columns = columns.size();

  // Resolve the selected columns into slots: time (optional), inputs, outputs.
  const bool has_time = options.sample_time <= 0;
  std::vector<std::size_t> slot_column;
  // A header that is not text or holds only numbers explains an unknown column.
  std::size_t bad_byte = 0;
  const std::string header_note =
      !IsValidUtf8(header, &bad_byte)
          ? fmt::format(
                " (the header row is not valid UTF-8 text: byte 0x{:02X} at offset {}; "
                "save the file as UTF-8 text)",
                static_cast<unsigned char>(header[bad_byte]), bad_byte)
      : numeric_header ? " (the first row holds numbers: is the header row missing?)"
                       : "";
  auto resolve = [&](const std::string& spec, const char* role) {
    try {
      slot_column.push_back(
          internal::ResolveColumn(spec, columns, fmt::format("{}:{}", path, header_line), role));
    } catch (const DataError& e) {
      throw DataError(e.what() + header_note);
    }
  };
  if (has_time) resolve(options.time_column, "time");
  for (const auto& s : options.input_columns) resolve(s, "input");
  for (const auto& s : options.output_columns) resolve(s, "output");
  const std::size_t num_slots = slot_column.size();
  // column -> first slot reading it (a column may feed several slots).
  std::vector<int> column_slot(num_columns, -1);
  for (std::size_t s = num_slots; s-- > 0;) column_slot[slot_column[s]] = static_cast<int>(s);

  // The samples are parsed straight into the columns of the result: time
  // (when read), inputs and outputs, with room for `capacity` rows. Reading
  // the whole file, the capacity is the number of lines left, so the columns
  // are allocated once and handed to the Dataset without a copy; reading
  // blocks, it is the block size and the storage is reused.
  const auto num_inputs = static_cast<Eigen::Index>(options.input_columns.size());
  const auto num_outputs = static_cast<Eigen::Index>(options.output_columns.size());
  Eigen::VectorXd time_store;
  Eigen::MatrixXd input_store, output_store;
  std::vector<double*> dest(num_slots);
  Eigen::Index capacity = 0;
  auto reserve = [&](Eigen::Index rows) {
    if (has_time) time_store.conservativeResize(rows);
    input_store.conservativeResize(rows, num_inputs);
    output_store.conservativeResize(rows, num_outputs);
    capacity = rows;
    std::size_t s = 0;
    if (has_time) dest[s++] = time_store.data();
    for (Eigen::Index c = 0; c < num_inputs; ++c) dest[s++] = input_store.col(c).data();
    for (Eigen::Index c = 0; c < num_outputs; ++c) dest[s++] = output_store.col(c).data();
    // One system call maps the pages of large columns, not a fault per page.
    const auto bytes = static_cast<std::size_t>(rows) * sizeof(double);
    if (bytes >= (1u << 20)) {
      for (double* column : dest) internal::PopulatePages(column, bytes, /*write=*/true);
    }
  };
  reserve(on_block ? static_cast<Eigen::Index>(block_rows) : CountLines(p, end));
  // slot -> the slot whose cell it copies (a column may feed several slots).
  std::vector<std::size_t> slot_source(num_slots);
  for (std::size_t s = 0; s < num_slots; ++s) {
    slot_source[s] = static_cast<std::size_t>(column_slot[slot_column[s]]);
  }
  std::vector<double> row(num_slots);
  std::vector<Eigen::Index> break_samples;
  std::vector<long> break_lines;
  long previous_line = -1;
  Eigen::Index n = 0;      // samples read
  Eigen::Index stored = 0;  // samples in the storage (the current block)
  double previous_time = 0.0;

  // The `stored` samples of the storage, the first of which is sample `first`.
  auto take_block = [&](Eigen::Index first) {
    const Eigen::Index rows = stored;
    CsvBlock b;
    b.first_sample = first;
    if (has_time) {
      b.time = time_store.head(rows);
    } else {
      b.time.resize(rows);
      for (Eigen::Index i = 0; i < rows; ++i) {
        b.time[i] = options.start_time + static_cast<double>(first + i) * options.sample_time;
      }
    }
    b.inputs = input_store.topRows(rows);
    b.outputs = output_store.topRows(rows);
    b.fraction_read =
        text.empty() ? 1.0 : static_cast<double>(p - text.data()) / static_cast<double>(text.size());
    stored = 0;
    return b;
  };

  auto cell_error = [&](std::size_t column, const std::string& what) {
    return DataError(
        fmt::format("{}:{}: column '{}': {}", path, line, Excerpt(columns[column].label), what));
  };

  // The general row parser: comments, blanks, quotes, '+' signs, runs of
  // blanks as delimiter, and every error message. Returns false for a line
  // without content.
  auto parse_row = [&](std::string_view raw) {
    const std::string_view content = LineContent(raw, options.comment);
    if (content.empty()) return false;
    const std::size_t cells =
        ForEachCell(content, delimiter, [&](std::size_t c, std::string_view cell) {
          if (c >= num_columns) return;
          const int slot = column_slot[c];
          if (slot < 0) return;
          cell = StripQuotes(Trim(cell));
          if (cell.empty()) throw cell_error(c, "missing value (empty cell)");
          const char* first = cell.data();
          const char* last = first + cell.size();
          if (*first == '+') ++first;
          double v = 0.0;
          const auto [ptr, ec] = std::from_chars(first, last, v);
          if (ec == std::errc::result_out_of_range) {
            throw cell_error(c, fmt::format("number out of range: '{}'", Excerpt(cell)));
          }
          if (ec != std::errc() || ptr != last) {
            const bool decimal_comma = delimiter != ',' && cell.find(',') != cell.npos;
            throw cell_error(
                c, fmt::format("not a number: '{}'{}", Excerpt(cell),
                               decimal_comma ? " (numbers need '.' as decimal point)" : ""));
          }
          if (std::isnan(v)) throw cell_error(c, fmt::format("NaN value '{}'", Excerpt(cell)));
          if (std::isinf(v)) throw cell_error(c, fmt::format("infinite value '{}'", Excerpt(cell)));
          row[static_cast<std::size_t>(slot)] = v;
        });
    if (cells != num_columns) {
      throw DataError(fmt::format(
          "{}:{}: row has {} cells but the header (line {}) has {} columns (ragged row or "
          "missing cells; delimiter {})",
          path, line, cells, header_line, num_columns, DelimiterName(delimiter)));
    }
    return true;
  };

  // The fast row parser for the common plain row "1.5,2,3e-2": every cell
  // read is a number that std::from_chars reads up to the next delimiter,
  // finite, with the right number of cells. It returns false for anything
  // else (blank line, comment, blanks, quotes, '+', bad cells), and the
  // general parser then reads the line and reports what is wrong: both give
  // the same values, only the general one throws.
  const bool fast = delimiter != ' ';
  const char comment = options.comment;
  auto parse_row_fast = [&](const char* q, const char* e) {
    if (e > q && e[-1] == '\r') --e;
    if (q == e) return false;
    for (std::size_t c = 0; c < num_columns; ++c) {
      const int slot = column_slot[c];
      if (slot >= 0) {
        double v;
        const auto [ptr, ec] = std::from_chars(q, e, v);
        if (ec != std::errc() || !std::isfinite(v)) return false;
        row[static_cast<std::size_t>(slot)] = v;
        q = ptr;
      } else {
        while (q < e && *q != delimiter) {
          if (*q == comment) return false;
          ++q;
        }
      }
      if (c + 1 < num_columns) {
        if (q == e || *q != delimiter) return false;
        ++q;
      } else if (q != e) {
        return false;
      }
    }
    return true;
  };

  while (p < end) {
    const char* const line_start = p;
    const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
    const char* const line_end = nl == nullptr ? end : static_cast<const char*>(nl);
    p = nl == nullptr ? end : line_end + 1;
    ++line;
    if (!(fast && parse_row_fast(line_start, line_end)) &&
        !parse_row(std::string_view(line_start, static_cast<std::size_t>(line_end - line_start)))) {
      continue;
    }
    if (has_time) {
      const double t = row[0];
      if (n > 0 && !(t > previous_time)) {
        throw DataError(fmt::format(
            "{}:{}: column '{}': time is not strictly increasing: t = {} after t = {} on line {}",
            path, line, Excerpt(columns[slot_column[0]].label), t, previous_time, previous_line));
      }
      previous_time = t;
    }
    if (stored == capacity) reserve(capacity + capacity / 2 + 16);
    for (std::size_t s = 0; s < num_slots; ++s) dest[s][stored] = row[slot_source[s]];
    ++stored;
    if (line != previous_line + 1) {
      break_samples.push_back(n);
      break_lines.push_back(line);
    }
    previous_line = line;
    ++n;
    if (on_block && stored == capacity) (*on_block)(take_block(n - stored));
  }
  if (n == 0) {
    throw DataError(
        fmt::format("{}:{}: header row only, the file has no data rows", path, header_line));
  }
  if (on_block) {
    if (stored > 0) (*on_block)(take_block(n - stored));
    return n;
  }

  // Blank and comment lines leave unused rows (a copy; none for plain files).
  if (n < capacity) reserve(n);
  if (!has_time) {
    time_store.resize(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      time_store[i] = options.start_time + static_cast<double>(i) * options.sample_time;
    }
  }
  auto channels = [&](std::size_t first_slot, std::size_t count) {
    std::vector<Channel> out;
    for (std::size_t s = first_slot; s < first_slot + count; ++s) {
      const auto& col = columns[slot_column[s]];
      out.push_back({col.name, col.unit});
    }
    return out;
  };
  Channel time_channel{"t", "s"};
  if (has_time) {
    const auto& col = columns[slot_column[0]];
    time_channel = {col.name, col.unit.empty() ? "s" : col.unit};
  }
  const std::size_t first_input = has_time ? 1 : 0;
  *data = Dataset(std::move(time_store), std::move(input_store), std::move(output_store),
                  channels(first_input, options.input_columns.size()),
                  channels(first_input + options.input_columns.size(),
                           options.output_columns.size()));
  data->set_time_channel(time_channel);
  data->set_source(path);
  data->set_source_lines(std::move(break_samples), std::move(break_lines));
  return n;
}

}  // namespace

Dataset ReadCsv(const std::string& path, const CsvReadOptions& options) {
  Dataset data;
  ReadCsvRows(path, options, 0, nullptr, &data);
  return data;
}

Eigen::Index ReadCsvBlocks(const std::string& path, const CsvReadOptions& options,
                           std::size_t block_rows,
                           const std::function<void(const CsvBlock&)>& on_block) {
  PNEUMID_CHECK(block_rows > 0, "ReadCsvBlocks: block_rows must be > 0, got {}", block_rows);
  PNEUMID_CHECK(static_cast<bool>(on_block), "ReadCsvBlocks: on_block must be callable");
  return ReadCsvRows(path, options, block_rows, &on_block, nullptr);
}

bool CsvWriteOptions::IsValid(std::string* error) const {
  if (delimiter != ',' && delimiter != ';' && delimiter != '\t' && delimiter != ' ') {
    if (error != nullptr) {
      *error = fmt::format("CsvWriteOptions: delimiter must be ',', ';', tab or ' ', got '{}'",
                           delimiter);
    }
    return false;
  }
  for (const auto& c : comments) {
    if (c.find('\n') != std::string::npos) {
      if (error != nullptr) *error = "CsvWriteOptions: a comment line contains a newline";
      return false;
    }
  }
  return true;
}

void WriteCsv(const Dataset& data, const std::string& path, const std::vector<CsvColumn>& extra,
              const CsvWriteOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "WriteCsv: {}", error);
  for (const auto& c : extra) {
    PNEUMID_CHECK(c.values.size() == data.size(),
                  "WriteCsv: extra column '{}' has {} values, the dataset has {} samples",
                  c.channel.name, c.values.size(), data.size());
  }
  std::vector<Channel> channels;
  std::vector<const double*> columns;
  channels.push_back(data.time_channel());
  columns.push_back(data.time().data());
  for (int i = 0; i < data.num_inputs(); ++i) {
    channels.push_back(data.input_channels()[static_cast<std::size_t>(i)]);
    columns.push_back(data.inputs().col(i).data());
  }
  for (int i = 0; i < data.num_outputs(); ++i) {
    channels.push_back(data.output_channels()[static_cast<std::size_t>(i)]);
    columns.push_back(data.outputs().col(i).data());
  }
  for (const auto& c : extra) {
    channels.push_back(c.channel);
    columns.push_back(c.values.data());
  }

  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!f) throw DataError(fmt::format("{}: cannot write: {}", path, std::strerror(errno)));
  fmt::memory_buffer buf;
  for (const auto& c : options.comments) fmt::format_to(std::back_inserter(buf), "# {}\n", c);
  for (std::size_t c = 0; c < channels.size(); ++c) {
    if (c > 0) buf.push_back(options.delimiter);
    const auto& ch = channels[c];
    if (ch.unit.empty()) {
      fmt::format_to(std::back_inserter(buf), "{}", ch.name);
    } else {
      fmt::format_to(std::back_inserter(buf), "{} [{}]", ch.name, ch.unit);
    }
  }
  buf.push_back('\n');
  auto flush = [&]() {
    if (std::fwrite(buf.data(), 1, buf.size(), f.get()) != buf.size()) {
      throw DataError(fmt::format("{}: write failed: {}", path, std::strerror(errno)));
    }
    buf.clear();
  };
  for (Eigen::Index i = 0; i < data.size(); ++i) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (c > 0) buf.push_back(options.delimiter);
      fmt::format_to(std::back_inserter(buf), "{}", columns[c][i]);
    }
    buf.push_back('\n');
    if (buf.size() > (1u << 20)) flush();
  }
  flush();
  if (std::fclose(f.release()) != 0) {
    throw DataError(fmt::format("{}: write failed: {}", path, std::strerror(errno)));
  }
}

}  // namespace pneumid
