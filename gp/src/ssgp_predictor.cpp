/// SSGP prediction from the cached posterior (formulas in ssgp.hpp), O(m D + m^2) per query.

#include <cmath>
#include <stdexcept>
#include <string>

#include "gpilqg/gp/ssgp.hpp"
#include "ssgp_sincos.hpp"

namespace gpilqg::gp {

void SsgpPredictor::predict(const VectorCRef& x, double* phi_out, double* c_out, double& mean,
                            double* variance, double* dmean, double* dvariance) const {
  const int D = input_dim();
  const int m = frequencies();
  if (x.size() != D)
    throw std::invalid_argument("SSGP prediction: the input has " + std::to_string(x.size()) +
                                " entries; expected " + std::to_string(D));
  Eigen::Map<Vector> phi(phi_out, 2 * m);
  Eigen::Map<Vector> c(c_out, 2 * m);
  phi.head(m).noalias() = S_ * x;  // z = S x, then [cos z; sin z] in place
  ssgp_detail::sincos_many(phi_out, phi_out, phi_out + m, m);
  mean = phi.dot(alpha_);
  // d/dx of sum_r (u_r cos z_r + v_r sin z_r) = sum_r (v_r cos z_r - u_r sin z_r) s_r.
  auto chain = [&](const auto& weights, double scale, double* out) {
    for (int d = 0; d < D; ++d) out[d] = 0.0;
    for (int r = 0; r < m; ++r) {
      const double g = scale * (weights(m + r) * phi(r) - weights(r) * phi(m + r));
      for (int d = 0; d < D; ++d) out[d] += g * S_(r, d);
    }
  };
  if (dmean != nullptr) chain(alpha_, 1.0, dmean);
  if (variance == nullptr) return;
  c.noalias() = C_ * phi;
  const double raw = phi.dot(c);
  const bool clamped = !(raw > 0.0);
  *variance = clamped ? 0.0 : raw;
  if (dvariance == nullptr) return;
  if (clamped) {
    for (int d = 0; d < D; ++d) dvariance[d] = 0.0;
    return;
  }
  chain(c, 2.0, dvariance);
}

}  // namespace gpilqg::gp
