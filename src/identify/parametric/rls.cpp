#include "pneumid/identify/parametric/rls.hpp"

#include "pneumid/common/check.hpp"

namespace pneumid {

bool RlsOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (!(forgetting_factor > 0.0 && forgetting_factor <= 1.0))
    return fail(fmt::format("forgetting_factor must be in (0, 1], got {}", forgetting_factor));
  if (!(initial_covariance > 0.0))
    return fail(fmt::format("initial_covariance must be > 0, got {}", initial_covariance));
  return true;
}

RecursiveLeastSquares::RecursiveLeastSquares(int num_parameters, const RlsOptions& options)
    : options_(options) {
  std::string error;
  PNEUMID_CHECK(options.IsValid(&error), "invalid RLS options: {}", error);
  PNEUMID_CHECK(num_parameters >= 1, "RLS needs >= 1 parameter, got {}", num_parameters);
  theta_.setZero(num_parameters);
  k_.setZero(num_parameters);
  pphi_.setZero(num_parameters);
  P_.setZero(num_parameters, num_parameters);
  Reset();
}

void RecursiveLeastSquares::Reset(const Eigen::VectorXd& theta0) {
  if (theta0.size() == 0) {
    theta_.setZero();
  } else {
    PNEUMID_CHECK(theta0.size() == theta_.size(), "theta0 needs {} entries, got {}", theta_.size(),
                  theta0.size());
    theta_ = theta0;
  }
  P_.setIdentity();
  P_ *= options_.initial_covariance;
  updates_ = 0;
}

double RecursiveLeastSquares::Update(const Eigen::Ref<const Eigen::VectorXd>& phi, double y) {
  eigen_assert(phi.size() == theta_.size());
  const double lambda = options_.forgetting_factor;
  const double e = y - phi.dot(theta_);
  pphi_.noalias() = P_ * phi;
  const double denom = lambda + phi.dot(pphi_);
  k_ = pphi_ / denom;
  theta_.noalias() += k_ * e;
  P_.noalias() -= k_ * pphi_.transpose();
  P_ /= lambda;
  // Keep P symmetric against rounding.
  for (Eigen::Index i = 0; i < P_.rows(); ++i)
    for (Eigen::Index j = i + 1; j < P_.cols(); ++j)
      P_(i, j) = P_(j, i) = 0.5 * (P_(i, j) + P_(j, i));
  ++updates_;
  return e;
}

RecursiveArx::RecursiveArx(const ArxOptions& orders, const RlsOptions& options)
    : orders_(orders), rls_(std::max(1, orders.NumParameters()), options) {
  std::string error;
  PNEUMID_CHECK(orders.IsValid(&error), "invalid ARX orders: {}", error);
  PNEUMID_CHECK(orders.nb.size() == 1, "RecursiveArx is single-input, got {} inputs",
                orders.nb.size());
  ypast_.setZero(std::max(1, orders.na));
  upast_.setZero(orders.nk[0] + orders.nb[0] + 1);
  phi_.setZero(orders.NumParameters());
}

double RecursiveArx::Update(double u, double y) {
  const int na = orders_.na, nb = orders_.nb[0], nk = orders_.nk[0];
  // upast_[j] = u(t - j) after the shift.
  for (Eigen::Index j = upast_.size() - 1; j > 0; --j) upast_[j] = upast_[j - 1];
  upast_[0] = u;
  double e = 0.0;
  if (seen_ >= orders_.FirstRow()) {
    for (int l = 0; l < na; ++l) phi_[l] = -ypast_[l];  // -y(t-1-l)
    for (int j = 0; j < nb; ++j) phi_[na + j] = upast_[nk + j];
    e = rls_.Update(phi_, y);
  }
  for (Eigen::Index l = ypast_.size() - 1; l > 0; --l) ypast_[l] = ypast_[l - 1];
  ypast_[0] = y;
  ++seen_;
  return e;
}

PolynomialModel RecursiveArx::Model(double Ts) const {
  PNEUMID_CHECK(Ts > 0, "sample time must be positive, got Ts = {}", Ts);
  PolynomialModel m;
  m.Ts = Ts;
  m.structure = "ARX";
  const int na = orders_.na, nb = orders_.nb[0], nk = orders_.nk[0];
  m.a = Eigen::VectorXd::Ones(na + 1);
  m.a.tail(na) = rls_.theta().head(na);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(nk + nb);
  b.tail(nb) = rls_.theta().segment(na, nb);
  m.b = {b};
  m.nk = {nk};
  return m;
}

}  // namespace pneumid
