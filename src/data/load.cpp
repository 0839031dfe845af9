#include "pneumid/data/load.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/common/strings.hpp"

namespace pneumid {
namespace {

std::string Extension(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return ToLower(path.substr(dot + 1));
}

DataFormat Resolve(DataFormat format, const std::string& path) {
  return format == DataFormat::kAuto ? DataFormatFromPath(path) : format;
}

}  // namespace

namespace {
constexpr EnumName<DataFormat> kDataFormatNames[] = {
    {DataFormat::kAuto, "auto"},
    {DataFormat::kCsv, "csv"},
    {DataFormat::kMat, "mat"},
    {DataFormat::kCsv, "txt"},
    {DataFormat::kCsv, "tsv"},
    {DataFormat::kCsv, "dat"},
};
}  // namespace

std::string ToString(DataFormat v) { return std::string(EnumToString(kDataFormatNames, v)); }

DataFormat DataFormatFromString(const std::string& name) {
  return EnumFromString(kDataFormatNames, name, "data format", /*ignore_case=*/true);
}

DataFormat DataFormatFromPath(const std::string& path) {
  const std::string ext = Extension(path);
  if (ext == "csv" || ext == "txt" || ext == "tsv" || ext == "dat") return DataFormat::kCsv;
  if (ext == "mat") return DataFormat::kMat;
  throw DataError(
      fmt::format("{}: unknown data file extension '{}' (expected .csv, .txt, .tsv, .dat or .mat)",
                  path, ext.empty() ? "" : "." + ext));
}

bool LoadOptions::IsValid(std::string* error) const {
  if (format == DataFormat::kMat) return ToMat().IsValid(error);
  if (!ToCsv().IsValid(error)) return false;
  return format != DataFormat::kAuto || ToMat().IsValid(error);
}

CsvReadOptions LoadOptions::ToCsv() const {
  CsvReadOptions o;
  o.delimiter = delimiter;
  o.comment = comment;
  o.time_column = time_column;
  o.input_columns = input_columns;
  o.output_columns = output_columns;
  o.sample_time = sample_time;
  o.start_time = start_time;
  return o;
}

MatReadOptions LoadOptions::ToMat() const {
  MatReadOptions o;
  o.time_variable = time_column;
  o.input_variables = input_columns;
  o.output_variables = output_columns;
  o.sample_time = sample_time;
  o.start_time = start_time;
  return o;
}

Dataset LoadDataset(const std::string& path, const LoadOptions& options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "LoadDataset: {}", error);
  // A missing file is reported as such, before its extension is looked at.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    throw DataError(fmt::format("{}: cannot open: {}", path, std::strerror(errno)));
  }
  if (S_ISDIR(st.st_mode)) {
    throw DataError(fmt::format("{}: is a directory, not a data file", path));
  }
  switch (Resolve(options.format, path)) {
    case DataFormat::kMat:
      return ReadMat(path, options.ToMat());
    default:
      return ReadCsv(path, options.ToCsv());
  }
}

void SaveDataset(const Dataset& data, const std::string& path, const SaveOptions& options) {
  switch (Resolve(options.format, path)) {
    case DataFormat::kMat:
      WriteMat(data, path, options.mat);
      break;
    default: {
      CsvWriteOptions csv = options.csv;
      if (options.format == DataFormat::kAuto && Extension(path) == "tsv" && csv.delimiter == ',') {
        csv.delimiter = '\t';
      }
      WriteCsv(data, path, {}, csv);
      break;
    }
  }
}

}  // namespace pneumid
