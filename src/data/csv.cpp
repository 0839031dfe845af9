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

/// The lines of a text, front to back.
struct LineCursor {
  const char* p;    ///< start of the next line
  const char* end;  ///< end of the text
  long line = 0;    ///< 1-based number of the line last returned (0: none yet)

  bool AtEnd() const { return !(p < end); }

  /// The next line (without '\n'); advances past it.
  std::string_view Next() {
    const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
    const char* line_end = nl == nullptr ? end : static_cast<const char*>(nl);
    std::string_view content(p, static_cast<std::size_t>(line_end - p));
    p = nl == nullptr ? end : line_end + 1;
    ++line;
    return content;
  }
};

/// The mapped text of a file without a UTF-8 byte order mark; throws DataError
/// for an empty file or one that is not 8-bit text.
std::string_view FileText(const std::string& path, const internal::MappedFile& file) {
  std::string_view text = file.view();
  if (text.size() >= 3 && std::memcmp(text.data(), "\xEF\xBB\xBF", 3) == 0) {
    text.remove_prefix(3);  // UTF-8 byte order mark
  }
  CheckTextEncoding(path, text);
  if (text.empty()) throw DataError(fmt::format("{}:1: empty file (expected a header row)", path));
  return text;
}

/// The header row of a file.
struct CsvHeader {
  std::string_view text;  ///< the row without comment and surrounding blanks
  long line = 0;          ///< its line number
  char delimiter = ' ';   ///< the cell delimiter (set or detected from the row)
  std::vector<internal::ColumnName> columns;
  bool numeric = true;  ///< every cell is a number: the header row is likely missing
};

/// Reads the header row, the first line with content, and advances `lines`
/// past it; throws DataError when there is none or it is too long or too wide.
CsvHeader ReadHeader(const std::string& path, const CsvReadOptions& options, LineCursor& lines) {
  CsvHeader header;
  while (!lines.AtEnd()) {
    header.text = LineContent(lines.Next(), options.comment);
    if (!header.text.empty()) break;
  }
  if (header.text.empty()) {
    throw DataError(fmt::format("{}:{}: empty file: no header row (only blank or comment lines)",
                                path, lines.line));
  }
  header.line = lines.line;
  // A carriage return inside the line (LineContent trims a trailing one):
  // the file ends its lines with CR alone (classic Mac OS), and its whole
  // content reads as one line.
  if (const std::size_t cr = header.text.find('\r'); cr != std::string_view::npos) {
    throw DataError(fmt::format(
        "{}:{}: the lines end with a carriage return alone (classic Mac OS line ends), so the "
        "file reads as one line; convert them, e.g. tr '\\r' '\\n' < {} > fixed.csv",
        path, header.line, path));
  }
  if (header.text.size() > kCsvMaxHeaderBytes) {
    throw DataError(fmt::format(
        "{}:{}: header row is {} bytes long (at most {}): not a header row; the file needs a "
        "first row of column names such as 't,u,y'",
        path, header.line, header.text.size(), kCsvMaxHeaderBytes));
  }
  header.delimiter = options.delimiter != '\0' ? options.delimiter : DetectDelimiter(header.text);
  ForEachCell(header.text, header.delimiter, [&](std::size_t index, std::string_view cell) {
    if (index >= kCsvMaxColumns) return;
    cell = StripQuotes(Trim(cell));
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
    header.numeric = header.numeric && ec == std::errc() && ptr == cell.data() + cell.size();
    header.columns.push_back(internal::ParseColumnName(std::string(cell)));
  });
  const std::size_t header_cells =
      ForEachCell(header.text, header.delimiter, [](std::size_t, auto) {});
  if (header_cells > kCsvMaxColumns) {
    throw DataError(fmt::format(
        "{}:{}: header row has {} columns (delimiter {}), more than the {} supported{}", path,
        header.line, header_cells, DelimiterName(header.delimiter), kCsvMaxColumns,
        header.numeric ? "; it holds numbers: is the header row missing?" : ""));
  }
  return header;
}

/// The selected columns as slots, in the order time (when read), inputs, outputs.
struct ColumnSlots {
  bool has_time = false;                 ///< the time column is read (no sample time given)
  std::vector<std::size_t> slot_column;  ///< slot -> its column
  std::vector<int> column_slot;          ///< column -> first slot reading it, or -1
  std::vector<std::size_t> slot_source;  ///< slot -> the slot whose cell it copies
  std::size_t size() const { return slot_column.size(); }
};

/// What explains an unknown column: a header that is not text or holds only
/// numbers ("" otherwise).
std::string UnknownColumnNote(const CsvHeader& header) {
  std::size_t bad_byte = 0;
  return !IsValidUtf8(header.text, &bad_byte)
             ? fmt::format(
                   " (the header row is not valid UTF-8 text: byte 0x{:02X} at offset {}; "
                   "save the file as UTF-8 text)",
                   static_cast<unsigned char>(header.text[bad_byte]), bad_byte)
         : header.numeric ? " (the first row holds numbers: is the header row missing?)"
                          : "";
}

/// Resolves the selected columns into slots; throws DataError (naming the
/// header line) for an unknown column.
ColumnSlots ResolveSlots(const std::string& path, const CsvReadOptions& options,
                         const CsvHeader& header) {
  ColumnSlots slots;
  slots.has_time = options.sample_time <= 0;
  const std::string header_note = UnknownColumnNote(header);
  auto resolve = [&](const std::string& spec, const char* role) {
    try {
      slots.slot_column.push_back(internal::ResolveColumn(
          spec, header.columns, fmt::format("{}:{}", path, header.line), role));
    } catch (const DataError& e) {
      throw DataError(e.what() + header_note);
    }
  };
  if (slots.has_time) resolve(options.time_column, "time");
  for (const auto& spec : options.input_columns) resolve(spec, "input");
  for (const auto& spec : options.output_columns) resolve(spec, "output");
  const std::size_t num_slots = slots.size();
  // column -> first slot reading it (a column may feed several slots).
  slots.column_slot.assign(header.columns.size(), -1);
  for (std::size_t s = num_slots; s-- > 0;) {
    slots.column_slot[slots.slot_column[s]] = static_cast<int>(s);
  }
  // slot -> the slot whose cell it copies (a column may feed several slots).
  slots.slot_source.resize(num_slots);
  for (std::size_t s = 0; s < num_slots; ++s) {
    slots.slot_source[s] = static_cast<std::size_t>(slots.column_slot[slots.slot_column[s]]);
  }
  return slots;
}

/// The samples are parsed straight into the columns of the result: time
/// (when read), inputs and outputs, with room for `capacity` rows. Reading
/// the whole file, the capacity is the number of lines left, so the columns
/// are allocated once and handed to the Dataset without a copy; reading
/// blocks, it is the block size and the storage is reused.
struct SampleStore {
  bool has_time = false;
  Eigen::Index num_inputs = 0;
  Eigen::Index num_outputs = 0;
  Eigen::VectorXd time;
  Eigen::MatrixXd inputs, outputs;
  std::vector<double*> slot_storage;  ///< slot -> first element of its column
  Eigen::Index capacity = 0;          ///< rows allocated
  Eigen::Index stored = 0;            ///< rows in use (the samples of the current block)

  SampleStore(bool read_time, Eigen::Index inputs_count, Eigen::Index outputs_count,
              std::size_t num_slots)
      : has_time(read_time),
        num_inputs(inputs_count),
        num_outputs(outputs_count),
        slot_storage(num_slots) {}

  /// Resizes the columns to `rows` rows, keeping their content.
  void Reserve(Eigen::Index rows) {
    if (has_time) time.conservativeResize(rows);
    inputs.conservativeResize(rows, num_inputs);
    outputs.conservativeResize(rows, num_outputs);
    capacity = rows;
    std::size_t s = 0;
    if (has_time) slot_storage[s++] = time.data();
    for (Eigen::Index c = 0; c < num_inputs; ++c) slot_storage[s++] = inputs.col(c).data();
    for (Eigen::Index c = 0; c < num_outputs; ++c) slot_storage[s++] = outputs.col(c).data();
    // One system call maps the pages of large columns, not a fault per page.
    const auto bytes = static_cast<std::size_t>(rows) * sizeof(double);
    if (bytes >= (1u << 20)) {
      for (double* column : slot_storage) internal::PopulatePages(column, bytes, /*write=*/true);
    }
  }
};

/// Hands over the `stored` samples of the store, the first of which is sample
/// `first`, and empties it.
CsvBlock TakeBlock(SampleStore& store, const CsvReadOptions& options, Eigen::Index first,
                   double fraction_read) {
  const Eigen::Index rows = store.stored;
  CsvBlock block;
  block.first_sample = first;
  if (store.has_time) {
    block.time = store.time.head(rows);
  } else {
    block.time.resize(rows);
    for (Eigen::Index i = 0; i < rows; ++i) {
      block.time[i] = options.start_time + static_cast<double>(first + i) * options.sample_time;
    }
  }
  block.inputs = store.inputs.topRows(rows);
  block.outputs = store.outputs.topRows(rows);
  block.fraction_read = fraction_read;
  store.stored = 0;
  return block;
}

/// Parses data rows into the values of the slots, row().
class RowParser {
 public:
  RowParser(const std::string& path, const CsvHeader& header, const ColumnSlots& slots,
            char comment)
      : path_(path),
        header_(header),
        column_slot_(slots.column_slot),
        num_columns_(header.columns.size()),
        delimiter_(header.delimiter),
        comment_(comment),
        fast_(header.delimiter != ' '),
        row_(slots.size()) {}

  /// Parses line number `line` into row(); false for a line without content.
  bool Parse(const char* line_start, const char* line_end, long line) {
    line_ = line;
    return (fast_ && ParseFast(line_start, line_end)) ||
           ParseGeneral(
               std::string_view(line_start, static_cast<std::size_t>(line_end - line_start)));
  }

  /// The values of the row last parsed, by slot.
  const std::vector<double>& row() const { return row_; }

 private:
  DataError CellError(std::size_t column, const std::string& what) const {
    return DataError(fmt::format("{}:{}: column '{}': {}", path_, line_,
                                 Excerpt(header_.columns[column].label), what));
  }

  /// The number in a cell of `column` (already trimmed and unquoted), or a
  /// DataError saying what is wrong with it.
  double ParseCell(std::size_t column, std::string_view cell) const {
    if (cell.empty()) throw CellError(column, "missing value (empty cell)");
    const char* first = cell.data();
    const char* last = first + cell.size();
    if (*first == '+') ++first;
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(first, last, value);
    if (ec == std::errc::result_out_of_range) {
      throw CellError(column, fmt::format("number out of range: '{}'", Excerpt(cell)));
    }
    if (ec != std::errc() || ptr != last) {
      const bool decimal_comma = delimiter_ != ',' && cell.find(',') != cell.npos;
      throw CellError(column,
                      fmt::format("not a number: '{}'{}", Excerpt(cell),
                                  decimal_comma ? " (numbers need '.' as decimal point)" : ""));
    }
    if (std::isnan(value)) throw CellError(column, fmt::format("NaN value '{}'", Excerpt(cell)));
    if (std::isinf(value)) {
      throw CellError(column, fmt::format("infinite value '{}'", Excerpt(cell)));
    }
    return value;
  }

  // The general row parser: comments, blanks, quotes, '+' signs, runs of
  // blanks as delimiter, and every error message. Returns false for a line
  // without content.
  bool ParseGeneral(std::string_view raw) {
    const std::string_view content = LineContent(raw, comment_);
    if (content.empty()) return false;
    const std::size_t cells =
        ForEachCell(content, delimiter_, [&](std::size_t c, std::string_view cell) {
          if (c >= num_columns_) return;
          const int slot = column_slot_[c];
          if (slot < 0) return;
          row_[static_cast<std::size_t>(slot)] = ParseCell(c, StripQuotes(Trim(cell)));
        });
    if (cells != num_columns_) {
      throw DataError(fmt::format(
          "{}:{}: row has {} cells but the header (line {}) has {} columns (ragged row or "
          "missing cells; delimiter {})",
          path_, line_, cells, header_.line, num_columns_, DelimiterName(delimiter_)));
    }
    return true;
  }

  // The fast row parser for the common plain row "1.5,2,3e-2": every cell
  // read is a number that std::from_chars reads up to the next delimiter,
  // finite, with the right number of cells. It returns false for anything
  // else (blank line, comment, blanks, quotes, '+', bad cells), and the
  // general parser then reads the line and reports what is wrong: both give
  // the same values, only the general one throws.
  bool ParseFast(const char* cursor, const char* line_end) {
    if (line_end > cursor && line_end[-1] == '\r') --line_end;
    if (cursor == line_end) return false;
    for (std::size_t c = 0; c < num_columns_; ++c) {
      const int slot = column_slot_[c];
      if (slot >= 0) {
        double value;
        const auto [ptr, ec] = std::from_chars(cursor, line_end, value);
        if (ec != std::errc() || !std::isfinite(value)) return false;
        row_[static_cast<std::size_t>(slot)] = value;
        cursor = ptr;
      } else {
        while (cursor < line_end && *cursor != delimiter_) {
          if (*cursor == comment_) return false;
          ++cursor;
        }
      }
      if (c + 1 < num_columns_) {
        if (cursor == line_end || *cursor != delimiter_) return false;
        ++cursor;
      } else if (cursor != line_end) {
        return false;
      }
    }
    return true;
  }

  const std::string& path_;
  const CsvHeader& header_;
  const std::vector<int>& column_slot_;
  const std::size_t num_columns_;
  const char delimiter_;
  const char comment_;
  const bool fast_;  ///< the fast parser applies (not for runs of blanks as delimiter)
  std::vector<double> row_;
  long line_ = 0;  ///< the line being parsed
};

/// The data rows read: their number and where the file's line numbering jumps.
struct RowsRead {
  Eigen::Index samples = 0;
  std::vector<Eigen::Index> break_samples;  ///< samples after skipped lines
  std::vector<long> break_lines;            ///< their line numbers
};

/// Reads the data rows after the header into `store` (handing full blocks to
/// `on_block` when given); throws DataError for a bad row, time that does
/// not increase, or no data rows.
RowsRead ReadDataRows(const std::string& path, const CsvReadOptions& options,
                      const CsvHeader& header, const ColumnSlots& slots, std::string_view text,
                      LineCursor& lines, SampleStore& store,
                      const std::function<void(const CsvBlock&)>* on_block) {
  RowParser parser(path, header, slots, options.comment);
  const std::vector<double>& row = parser.row();
  const std::size_t num_slots = slots.size();
  auto fraction_read = [&] {
    return text.empty()
               ? 1.0
               : static_cast<double>(lines.p - text.data()) / static_cast<double>(text.size());
  };
  RowsRead read;
  Eigen::Index& samples = read.samples;
  long previous_line = -1;
  double previous_time = 0.0;
  while (!lines.AtEnd()) {
    const std::string_view raw = lines.Next();
    const long line = lines.line;
    if (!parser.Parse(raw.data(), raw.data() + raw.size(), line)) continue;
    if (slots.has_time) {
      const double t = row[0];
      if (samples > 0 && !(t > previous_time)) {
        throw DataError(fmt::format(
            "{}:{}: column '{}': time is not strictly increasing: t = {} after t = {} on line {}",
            path, line, Excerpt(header.columns[slots.slot_column[0]].label), t, previous_time,
            previous_line));
      }
      previous_time = t;
    }
    if (store.stored == store.capacity) store.Reserve(store.capacity + store.capacity / 2 + 16);
    for (std::size_t s = 0; s < num_slots; ++s) {
      store.slot_storage[s][store.stored] = row[slots.slot_source[s]];
    }
    ++store.stored;
    if (line != previous_line + 1) {
      read.break_samples.push_back(samples);
      read.break_lines.push_back(line);
    }
    previous_line = line;
    ++samples;
    if (on_block && store.stored == store.capacity) {
      (*on_block)(TakeBlock(store, options, samples - store.stored, fraction_read()));
    }
  }
  if (samples == 0) {
    throw DataError(
        fmt::format("{}:{}: header row only, the file has no data rows", path, header.line));
  }
  if (on_block && store.stored > 0) {
    (*on_block)(TakeBlock(store, options, samples - store.stored, fraction_read()));
  }
  return read;
}

/// The channels of `count` slots from `first_slot` on, named after their columns.
std::vector<Channel> SlotChannels(const CsvHeader& header, const ColumnSlots& slots,
                                  std::size_t first_slot, std::size_t count) {
  std::vector<Channel> channels;
  for (std::size_t s = first_slot; s < first_slot + count; ++s) {
    const auto& column = header.columns[slots.slot_column[s]];
    channels.push_back({column.name, column.unit});
  }
  return channels;
}

/// Moves the samples read into *data, with the channels of the header.
void AssembleDataset(const std::string& path, const CsvReadOptions& options,
                     const CsvHeader& header, const ColumnSlots& slots, SampleStore& store,
                     RowsRead read, Dataset* data) {
  const Eigen::Index samples = read.samples;
  // Blank and comment lines leave unused rows (a copy; none for plain files).
  if (samples < store.capacity) store.Reserve(samples);
  if (!slots.has_time) {
    store.time.resize(samples);
    for (Eigen::Index i = 0; i < samples; ++i) {
      store.time[i] = options.start_time + static_cast<double>(i) * options.sample_time;
    }
  }
  Channel time_channel{"t", "s"};
  if (slots.has_time) {
    const auto& column = header.columns[slots.slot_column[0]];
    time_channel = {column.name, column.unit.empty() ? "s" : column.unit};
  }
  const std::size_t first_input = slots.has_time ? 1 : 0;
  *data = Dataset(std::move(store.time), std::move(store.inputs), std::move(store.outputs),
                  SlotChannels(header, slots, first_input, options.input_columns.size()),
                  SlotChannels(header, slots, first_input + options.input_columns.size(),
                               options.output_columns.size()));
  data->set_time_channel(time_channel);
  data->set_source(path);
  data->set_source_lines(std::move(read.break_samples), std::move(read.break_lines));
}

// The reader behind ReadCsv and ReadCsvBlocks. With `on_block`, the samples are
// handed over in blocks of at most `block_rows` and not kept (*data is left
// empty); without, they are returned in *data.
Eigen::Index ReadCsvRows(const std::string& path, const CsvReadOptions& options,
                         std::size_t block_rows,
                         const std::function<void(const CsvBlock&)>* on_block, Dataset* data) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "ReadCsv: {}", error);
  internal::MappedFile file(path);
  const std::string_view text = FileText(path, file);
  LineCursor lines{text.data(), text.data() + text.size()};
  const CsvHeader header = ReadHeader(path, options, lines);
  const ColumnSlots slots = ResolveSlots(path, options, header);
  SampleStore store(slots.has_time, static_cast<Eigen::Index>(options.input_columns.size()),
                    static_cast<Eigen::Index>(options.output_columns.size()), slots.size());
  store.Reserve(on_block ? static_cast<Eigen::Index>(block_rows) : CountLines(lines.p, lines.end));
  RowsRead read = ReadDataRows(path, options, header, slots, text, lines, store, on_block);
  const Eigen::Index samples = read.samples;
  if (!on_block) AssembleDataset(path, options, header, slots, store, std::move(read), data);
  return samples;
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
