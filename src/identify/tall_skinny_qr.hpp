// Private helper of the ARX and subspace estimators: the triangular factor of
// a tall matrix accumulated row block by row block (see arx.hpp for the
// method and its reference [3], Demmel et al. 2012).
#pragma once

#include <Eigen/Core>

namespace pneumid::internal {

/// Triangular factor R of a tall matrix M = Q R given row block by row block
/// (Householder reflections of [R; block]); memory independent of the number
/// of rows.
class TallSkinnyQr {
 public:
  /// @throws InvalidArgument unless cols >= 1.
  explicit TallSkinnyQr(int cols);
  /// Appends rows (m x cols). @throws InvalidArgument on a column mismatch.
  void AddRows(const Eigen::Ref<const Eigen::MatrixXd>& rows);
  /// cols x cols upper-triangular factor (R' R = M' M).
  const Eigen::MatrixXd& R() const { return R_; }
  long long num_rows() const { return num_rows_; }

 private:
  Eigen::MatrixXd R_;
  Eigen::MatrixXd block_;
  long long num_rows_ = 0;
};

}  // namespace pneumid::internal
