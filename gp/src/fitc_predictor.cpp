/// FITC prediction from the cached posterior (formulas in fitc.hpp), O(M D + M^2) per query.

#include <cmath>
#include <stdexcept>
#include <string>

#include "gpilqg/gp/fitc.hpp"

namespace gpilqg::gp {

void FitcPredictor::predict(const VectorCRef& x, double* k_out, double* c_out, double* xs_out, double& mean,
                            double* variance, double* dmean, double* dvariance) const {
  const int D = input_dim();
  const int M = inducing();
  if (x.size() != D)
    throw std::invalid_argument("FITC prediction: the input has " + std::to_string(x.size()) +
                                " entries; expected " + std::to_string(D));
  Eigen::Map<Vector> k(k_out, M);
  Eigen::Map<Vector> c(c_out, M);
  Eigen::Map<Vector> xs(xs_out, D);
  xs = x.cwiseProduct(inv_lengthscale_);

  // k_m = sf2 exp(-0.5 |xu_m - x|^2 / l^2).
  for (int m = 0; m < M; ++m) {
    double d2 = 0.0;
    for (int d = 0; d < D; ++d) {
      const double diff = scaled_inducing_(m, d) - xs(d);
      d2 += diff * diff;
    }
    k(m) = sf2_ * std::exp(-0.5 * d2);
  }
  const double bk = k.dot(beta_);
  mean = bk;
  if (dmean != nullptr) {
    // dmu/dx_d = sum_m beta_m k_m (xu_md - x_d) / l_d^2 (on scaled inputs: times 1/l_d).
    c = beta_.cwiseProduct(k);
    for (int d = 0; d < D; ++d)
      dmean[d] = (scaled_inducing_.col(d).dot(c) - xs(d) * bk) * inv_lengthscale_(d);
  }
  if (variance == nullptr) return;
  c.noalias() = C_ * k;
  const double ck = k.dot(c);
  const double raw = sf2_ + ck;
  const bool clamped = !(raw > 0.0);
  *variance = clamped ? 0.0 : raw;
  if (dvariance == nullptr) return;
  if (clamped) {
    for (int d = 0; d < D; ++d) dvariance[d] = 0.0;
    return;
  }
  // ds2/dx_d = 2 sum_m c_m k_m (xu_md - x_d) / l_d^2,  c = C k.
  c.array() *= k.array();
  for (int d = 0; d < D; ++d)
    dvariance[d] = 2.0 * (scaled_inducing_.col(d).dot(c) - xs(d) * ck) * inv_lengthscale_(d);
}

}  // namespace gpilqg::gp
