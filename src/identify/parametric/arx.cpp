#include "pneumid/identify/parametric/arx.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <Eigen/SVD>

#include "pneumid/common/check.hpp"
#include "../tall_skinny_qr.hpp"

namespace pneumid {

namespace {

constexpr Eigen::Index kBlockRows = 256;

// Householder reduction of [R; B] to upper-triangular form, R (p x p, column
// major, leading dimension p) updated in place, B (m x p, column major, leading
// dimension ld) destroyed. Compiled for AVX2/FMA when the processor has them.
__attribute__((target_clones("arch=x86-64-v3", "default"))) void ReduceKernel(double* R, int p,
                                                                              double* B,
                                                                              Eigen::Index ld,
                                                                              Eigen::Index m) {
  for (int j = 0; j < p; ++j) {
    double* xb = B + j * ld;
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    Eigen::Index r = 0;
    for (; r + 4 <= m; r += 4) {
      s0 += xb[r] * xb[r];
      s1 += xb[r + 1] * xb[r + 1];
      s2 += xb[r + 2] * xb[r + 2];
      s3 += xb[r + 3] * xb[r + 3];
    }
    for (; r < m; ++r) s0 += xb[r] * xb[r];
    const double sigma = (s0 + s1) + (s2 + s3);
    if (sigma == 0.0) continue;
    const double x0 = R[j + j * p];
    // A column that is zero up to rounding (exactly collinear columns, e.g. a
    // constant input in many Hankel columns) leaves residuals that shrink by
    // ~eps per column; once x0^2 + sigma is subnormal, beta = 2 / (v0^2 + sigma)
    // overflows and 0 * inf spreads NaN through R. Such a column is zero.
    if (x0 * x0 + sigma < std::numeric_limits<double>::min()) continue;
    const double alpha = -std::copysign(std::sqrt(x0 * x0 + sigma), x0);
    const double v0 = x0 - alpha;
    const double beta = 2.0 / (v0 * v0 + sigma);
    R[j + j * p] = alpha;
    for (int k = j + 1; k < p; ++k) {
      double* bk = B + k * ld;
      double t0 = 0, t1 = 0, t2 = 0, t3 = 0;
      r = 0;
      for (; r + 4 <= m; r += 4) {
        t0 += xb[r] * bk[r];
        t1 += xb[r + 1] * bk[r + 1];
        t2 += xb[r + 2] * bk[r + 2];
        t3 += xb[r + 3] * bk[r + 3];
      }
      for (; r < m; ++r) t0 += xb[r] * bk[r];
      const double s = beta * (v0 * R[j + k * p] + ((t0 + t1) + (t2 + t3)));
      R[j + k * p] -= s * v0;
      for (r = 0; r < m; ++r) bk[r] -= s * xb[r];
    }
  }
}

}  // namespace

namespace internal {

TallSkinnyQr::TallSkinnyQr(int cols) {
  PNEUMID_CHECK(cols >= 1, "a QR factorization needs >= 1 column, got {}", cols);
  R_ = Eigen::MatrixXd::Zero(cols, cols);
  block_.resize(kBlockRows, cols);
}

void TallSkinnyQr::AddRows(const Eigen::Ref<const Eigen::MatrixXd>& rows) {
  PNEUMID_CHECK(rows.cols() == R_.cols(), "rows need {} columns, got {}", R_.cols(), rows.cols());
  for (Eigen::Index r0 = 0; r0 < rows.rows(); r0 += kBlockRows) {
    const Eigen::Index m = std::min(kBlockRows, rows.rows() - r0);
    block_.topRows(m) = rows.middleRows(r0, m);
    ReduceKernel(R_.data(), static_cast<int>(R_.cols()), block_.data(), kBlockRows, m);
    num_rows_ += m;
  }
}

}  // namespace internal

bool ArxOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& msg) {
    if (error) *error = msg;
    return false;
  };
  if (na < 0) return fail(fmt::format("na must be >= 0, got {}", na));
  if (nb.empty()) return fail("nb needs one entry per input, got none");
  if (nk.size() != nb.size())
    return fail(fmt::format("nb and nk need one entry per input: {} vs {}", nb.size(), nk.size()));
  for (std::size_t i = 0; i < nb.size(); ++i) {
    if (nb[i] < 0) return fail(fmt::format("nb must be >= 0, got {} (input {})", nb[i], i));
    if (nk[i] < 0) return fail(fmt::format("nk must be >= 0, got {} (input {})", nk[i], i));
  }
  if (NumParameters() == 0) return fail("na = nb = 0: nothing to estimate");
  if (!(excitation_warning_condition > 1.0))
    return fail(fmt::format("excitation_warning_condition must be > 1, got {}",
                            excitation_warning_condition));
  if (!(rank_tolerance > 0.0 && rank_tolerance < 1.0))
    return fail(fmt::format("rank_tolerance must be in (0, 1), got {}", rank_tolerance));
  return true;
}

int ArxOptions::NumParameters() const {
  int d = na;
  for (int n : nb) d += n;
  return d;
}

int ArxOptions::FirstRow() const {
  int n0 = na;
  for (std::size_t i = 0; i < nb.size(); ++i)
    if (nb[i] > 0) n0 = std::max(n0, nk[i] + nb[i] - 1);
  return n0;
}

ArxAccumulator::ArxAccumulator(const ArxOptions& options) : options_(options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid ARX options: {}", error);
  d_ = options.NumParameters();
  n0_ = options.FirstRow();
  R_ = Eigen::MatrixXd::Zero(d_ + 1, d_ + 1);
  block_.resize(kBlockRows, d_ + 1);
}

void ArxAccumulator::BeginExperiment() {
  seen_ = 0;
  hist_y_.resize(0);
  hist_u_.resize(0, 0);
}

void ArxAccumulator::ReduceBlock(double* block, Eigen::Index rows) {
  ReduceKernel(R_.data(), d_ + 1, block, kBlockRows, rows);
  num_rows_ += rows;
}

void ArxAccumulator::AddRows(const Eigen::Ref<const Eigen::MatrixXd>& rows) {
  PNEUMID_CHECK(rows.cols() == d_ + 1, "rows need {} columns (parameters + target), got {}", d_ + 1,
                rows.cols());
  for (Eigen::Index r0 = 0; r0 < rows.rows(); r0 += kBlockRows) {
    const Eigen::Index m = std::min(kBlockRows, rows.rows() - r0);
    block_.topRows(m) = rows.middleRows(r0, m);
    ReduceBlock(block_.data(), m);
  }
}

void ArxAccumulator::AddSamples(const Eigen::Ref<const Eigen::VectorXd>& y,
                                const Eigen::Ref<const Eigen::MatrixXd>& u) {
  const int nu = static_cast<int>(options_.nb.size());
  PNEUMID_CHECK(u.cols() == nu, "the ARX orders are for {} input(s), the data have {}", nu,
                u.cols());
  PNEUMID_CHECK(u.rows() == y.size(), "input and output lengths differ: {} vs {}", u.rows(),
                y.size());
  PNEUMID_CHECK(y.allFinite() && u.allFinite(), "the data contain a non-finite value");
  const Eigen::Index n = y.size();
  if (n == 0) return;
  const Eigen::Index h = hist_y_.size();
  Eigen::VectorXd wy_store;
  Eigen::MatrixXd wu_store;
  const double* wy;
  const double* wu;
  Eigen::Index ldu;
  if (h == 0) {
    wy = y.data();
    wu = u.data();
    ldu = u.outerStride();
  } else {
    wy_store.resize(h + n);
    wy_store << hist_y_, y;
    wu_store.resize(h + n, nu);
    wu_store << hist_u_, u;
    wy = wy_store.data();
    wu = wu_store.data();
    ldu = wu_store.outerStride();
  }
  const long long g0 = seen_ - h;
  const Eigen::Index begin = std::max<Eigen::Index>(h, n0_ - g0);
  const Eigen::Index end = h + n;
  const int na = options_.na;
  for (Eigen::Index t0 = begin; t0 < end; t0 += kBlockRows) {
    const Eigen::Index m = std::min(kBlockRows, end - t0);
    double* B = block_.data();
    int col = 0;
    for (int l = 1; l <= na; ++l, ++col) {
      double* dst = B + col * kBlockRows;
      const double* src = wy + t0 - l;
      for (Eigen::Index r = 0; r < m; ++r) dst[r] = -src[r];
    }
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < options_.nb[i]; ++j, ++col) {
        double* dst = B + col * kBlockRows;
        const double* src = wu + i * ldu + t0 - options_.nk[i] - j;
        std::copy(src, src + m, dst);
      }
    }
    std::copy(wy + t0, wy + t0 + m, B + col * kBlockRows);
    ReduceBlock(B, m);
  }
  // Keep the last n0 samples of the experiment as history for the next chunk.
  const Eigen::Index keep = std::min<Eigen::Index>(n0_, end);
  if (keep > 0) {
    Eigen::VectorXd ny = Eigen::Map<const Eigen::VectorXd>(wy + end - keep, keep);
    Eigen::MatrixXd nu_hist(keep, nu);
    for (int i = 0; i < nu; ++i)
      nu_hist.col(i) = Eigen::Map<const Eigen::VectorXd>(wu + i * ldu + end - keep, keep);
    hist_y_ = std::move(ny);
    hist_u_ = std::move(nu_hist);
  }
  seen_ += n;
}

ArxResult ArxAccumulator::Solve(double Ts) const {
  PNEUMID_CHECK(Ts > 0.0, "sample time must be positive, got Ts = {}", Ts);
  ArxResult result;
  EstimationSummary& s = result.summary;
  s.num_rows = num_rows_;
  s.num_parameters = d_;
  PolynomialModel& m = result.model;
  m.Ts = Ts;
  m.structure = "ARX";
  const int nu = static_cast<int>(options_.nb.size());
  if (num_rows_ <= d_) {
    s.termination = Termination::kFailure;
    s.message = fmt::format("{} regression rows for {} parameters: need more data", num_rows_, d_);
    return result;
  }
  const Eigen::MatrixXd R11 = R_.topLeftCorner(d_, d_).triangularView<Eigen::Upper>();
  const Eigen::VectorXd r12 = R_.col(d_).head(d_);
  const double rho = R_(d_, d_);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(R11, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  const double smax = sv[0];
  const double smin = sv[d_ - 1];
  s.condition_number = smin > 0 ? smax / smin : std::numeric_limits<double>::infinity();
  Eigen::VectorXd colnorm = R11.colwise().norm().transpose();
  {
    Eigen::VectorXd inv = colnorm.unaryExpr([](double v) { return v > 0 ? 1.0 / v : 0.0; });
    Eigen::JacobiSVD<Eigen::MatrixXd> svs(R11 * inv.asDiagonal());
    const Eigen::VectorXd ss = svs.singularValues();
    s.scaled_condition_number =
        ss[d_ - 1] > 0 ? ss[0] / ss[d_ - 1] : std::numeric_limits<double>::infinity();
  }
  int rank = 0;
  for (Eigen::Index i = 0; i < d_; ++i)
    if (sv[i] > options_.rank_tolerance * smax) ++rank;
  Eigen::VectorXd theta;
  double sse = rho * rho;
  if (smax == 0.0) {
    s.termination = Termination::kFailure;
    s.message = "all regressors are zero";
    return result;
  }
  if (rank == d_) {
    theta = R11.triangularView<Eigen::Upper>().solve(r12);
    s.termination = Termination::kConvergence;
    s.message = "least squares by Householder QR";
  } else {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd2(R11, Eigen::ComputeThinU | Eigen::ComputeThinV);
    svd2.setThreshold(options_.rank_tolerance);
    theta = svd2.solve(r12);
    sse += (r12 - R11 * theta).squaredNorm();
    s.termination = Termination::kRankDeficient;
    s.message = fmt::format(
        "regressors of rank {} < {} parameters (input not persistently exciting or orders too "
        "high): minimum-norm solution",
        rank, d_);
    s.warnings.push_back(s.message);
  }
  const double N = static_cast<double>(num_rows_);
  s.loss = sse / N;
  const double lambda = sse / (N - d_);
  m.noise_variance = lambda;
  if (rank == d_) {
    Eigen::MatrixXd Rinv =
        R11.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(d_, d_));
    m.covariance = lambda * Rinv * Rinv.transpose();
  }
  if (s.scaled_condition_number > options_.excitation_warning_condition)
    s.warnings.push_back(fmt::format(
        "poor excitation: the scaled condition number of the regressors is {:.3g} (> {:.3g}); "
        "the estimate is sensitive to noise, use a richer input (e.g. PRBS) or lower orders",
        s.scaled_condition_number, options_.excitation_warning_condition));
  m.a = Eigen::VectorXd::Ones(options_.na + 1);
  m.a.tail(options_.na) = theta.head(options_.na);
  int off = options_.na;
  for (int i = 0; i < nu; ++i) {
    Eigen::VectorXd bi = Eigen::VectorXd::Zero(options_.nk[i] + options_.nb[i]);
    bi.tail(options_.nb[i]) = theta.segment(off, options_.nb[i]);
    off += options_.nb[i];
    m.b.push_back(bi);
    m.nk.push_back(options_.nk[i]);
  }
  return result;
}

namespace {

double CommonSampleTime(const std::vector<Dataset>& experiments) {
  PNEUMID_CHECK(!experiments.empty(), "no experiment given");
  const double Ts = experiments[0].SampleTime();
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    experiments[e].RequireUniform();
    PNEUMID_CHECK(std::abs(experiments[e].SampleTime() - Ts) <= 1e-6 * Ts,
                  "experiments have different sample times: {} s and {} s", Ts,
                  experiments[e].SampleTime());
    PNEUMID_CHECK(experiments[e].num_inputs() == experiments[0].num_inputs(),
                  "experiments have different numbers of inputs: {} and {}",
                  experiments[0].num_inputs(), experiments[e].num_inputs());
  }
  return Ts;
}

}  // namespace

ArxResult EstimateArx(const std::vector<Dataset>& experiments, const ArxOptions& options,
                      int output) {
  const double Ts = CommonSampleTime(experiments);
  ArxAccumulator acc(options);
  for (const auto& e : experiments) {
    PNEUMID_CHECK(e.num_inputs() == static_cast<int>(options.nb.size()),
                  "the ARX orders are for {} input(s), the data have {}", options.nb.size(),
                  e.num_inputs());
    PNEUMID_CHECK(output >= 0 && output < e.num_outputs(), "output {} out of range [0, {})", output,
                  e.num_outputs());
    e.RequireSamples(options.FirstRow() + 1, "ARX");
    acc.BeginExperiment();
    acc.AddSamples(e.outputs().col(output), e.inputs());
  }
  return acc.Solve(Ts);
}

ArxResult EstimateArx(const Dataset& data, const ArxOptions& options, int output) {
  return EstimateArx(std::vector<Dataset>{data}, options, output);
}

ArxResult EstimateArx(const Eigen::VectorXd& y, const Eigen::MatrixXd& u, double Ts,
                      const ArxOptions& options) {
  ArxAccumulator acc(options);
  acc.AddSamples(y, u);
  return acc.Solve(Ts);
}

void ArxRegressors(const Eigen::VectorXd& y, const Eigen::MatrixXd& u, const ArxOptions& options,
                   Eigen::MatrixXd* phi, Eigen::VectorXd* target) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid ARX options: {}", error);
  PNEUMID_CHECK(u.cols() == static_cast<int>(options.nb.size()),
                "the ARX orders are for {} input(s), the data have {}", options.nb.size(),
                u.cols());
  PNEUMID_CHECK(u.rows() == y.size(), "input and output lengths differ: {} vs {}", u.rows(),
                y.size());
  const Eigen::Index n0 = options.FirstRow();
  const Eigen::Index rows = std::max<Eigen::Index>(0, y.size() - n0);
  phi->resize(rows, options.NumParameters());
  target->resize(rows);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const Eigen::Index t = n0 + r;
    int col = 0;
    for (int l = 1; l <= options.na; ++l) (*phi)(r, col++) = -y[t - l];
    for (Eigen::Index i = 0; i < u.cols(); ++i)
      for (int j = 0; j < options.nb[i]; ++j) (*phi)(r, col++) = u(t - options.nk[i] - j, i);
    (*target)[r] = y[t];
  }
}

}  // namespace pneumid
