#include "pneumid/identify/parametric/arx_streaming.hpp"

#include <filesystem>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/data/csv.hpp"

namespace pneumid {

bool StreamingArxOptions::IsValid(std::string* error) const {
  if (!arx.IsValid(error)) return false;
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (arx.nb.size() != 1) return fail("streaming ARX is single-input (one nb, one nk)");
  if (sample_time < 0) return fail(fmt::format("sample_time must be >= 0, got {}", sample_time));
  if (block_rows < 1) return fail(fmt::format("block_rows must be >= 1, got {}", block_rows));
  if (input_column.empty() || output_column.empty()) return fail("column names must not be empty");
  return true;
}

StreamingArxResult EstimateArxFromFile(const std::string& path, const StreamingArxOptions& o) {
  std::string error;
  PNEUMID_CHECK(o.IsValid(&error), "invalid streaming ARX options: {}", error);
  CsvReadOptions csv;
  csv.delimiter = o.delimiter;
  csv.time_column = o.time_column;
  csv.input_columns = {o.input_column};
  csv.output_columns = {o.output_column};
  csv.sample_time = o.sample_time;

  ArxAccumulator acc(o.arx);
  StreamingArxResult result;
  // The sample time: given, or the first time step of the file (the reader
  // checks that time increases strictly).
  double Ts = o.sample_time;
  double t0 = 0.0;
  result.num_samples = ReadCsvBlocks(path, csv, o.block_rows, [&](const CsvBlock& b) {
    for (Eigen::Index i = 0; o.sample_time <= 0.0 && b.first_sample + i < 2 && i < b.time.size();
         ++i) {
      if (b.first_sample + i == 0) {
        t0 = b.time[i];
      } else {
        Ts = b.time[i] - t0;
      }
    }
    acc.AddSamples(b.outputs.col(0), b.inputs);
    if (o.progress) o.progress(b.fraction_read);
  });
  std::error_code ec;
  result.bytes = static_cast<double>(std::filesystem::file_size(path, ec));
  if (Ts <= 0.0) {
    throw DataError(
        fmt::format("{}: cannot determine the sample time from column '{}' (need two samples)",
                    path, o.time_column));
  }
  if (result.num_samples <= o.arx.FirstRow()) {
    throw DataError(fmt::format("{}: {} samples are too few for ARX", path, result.num_samples));
  }
  result.arx = acc.Solve(Ts);
  return result;
}

}  // namespace pneumid
