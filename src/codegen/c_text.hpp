// Private to the codegen area: C source text shared by the controller and
// plant generators.
#pragma once

#include <cctype>
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <Eigen/Core>

#include "pneumid/common/check.hpp"

namespace pneumid::internal {

/// A C literal of v that reads back exactly: %.17g for double, %.9g with an
/// f suffix for float (rounded to float first), always with a '.' or an
/// exponent, negative values in parentheses; "PFX_INF" for infinities.
/// @throws InvalidArgument for NaN or a value that overflows float.
inline std::string CLiteral(double v, bool is_float) {
  if (std::isinf(v)) return v > 0 ? "PFX_INF" : "(-PFX_INF)";
  PNEUMID_CHECK(std::isfinite(v), "cannot generate code for a non-finite constant ({})", v);
  std::string s;
  if (is_float) {
    const float f = static_cast<float>(v);
    PNEUMID_CHECK(std::isfinite(f), "the constant {} overflows single precision; use double", v);
    s = fmt::format("{:.9g}", f);
  } else {
    s = fmt::format("{:.17g}", v);
  }
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  if (is_float) s += "f";
  return v < 0 ? "(" + s + ")" : s;
}

/// The entries of m in column-major order as an initializer list body, four
/// per line; `min_entries` pads with zeros (C has no empty arrays).
inline std::string CInitializer(const Eigen::Ref<const Eigen::MatrixXd>& m, bool is_float,
                                Eigen::Index min_entries = 1) {
  const Eigen::Index n = m.size(), stored = std::max(n, min_entries);
  std::string body;
  for (Eigen::Index i = 0; i < stored; ++i) {
    const double v = i < n ? m(i % m.rows(), i / m.rows()) : 0.0;
    body += (i % 4 == 0 ? "\n    " : " ") + CLiteral(v, is_float) + (i + 1 < stored ? "," : "");
  }
  return body;
}

inline std::string Upper(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return s;
}

}  // namespace pneumid::internal
