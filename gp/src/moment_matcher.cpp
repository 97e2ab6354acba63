/// @file moment_matcher.cpp
/// MomentMatcher::propagate: what every implementation shares around its maths — checking mu and
/// Sigma, sizing the result blocks, and refusing to return a non-finite number.

#include "gpilqg/gp/moment_matcher.hpp"

#include <stdexcept>
#include <string>

namespace gpilqg::gp {

void MomentMatcher::propagate(const VectorCRef& mu, const MatrixCRef& sigma, MomentMatch& out,
                              MomentDerivatives derivatives) const {
  const Eigen::Index d = input_dim();
  const Eigen::Index e = output_dim();
  // The prefix of every message, built only when one is thrown (propagate must not allocate).
  const auto who = [this] { return std::string(name()) + "::propagate: "; };
  if (mu.size() != d)
    throw std::invalid_argument(who() + "mu has " + std::to_string(mu.size()) + " entries, expected D = " +
                                std::to_string(d));
  if (sigma.rows() != d || sigma.cols() != d)
    throw std::invalid_argument(who() + "Sigma is " + std::to_string(sigma.rows()) + " x " +
                                std::to_string(sigma.cols()) + ", expected D x D = " + std::to_string(d) + " x " +
                                std::to_string(d));
  if (!mu.allFinite()) throw std::invalid_argument(who() + "mu has a non-finite entry");
  if (!sigma.allFinite()) throw std::invalid_argument(who() + "Sigma has a non-finite entry");

  const bool with_derivatives = derivatives == MomentDerivatives::All;
  out.has_derivatives = false;
  out.mean.resize(e);
  out.covariance.resize(e, e);
  out.cross_covariance.resize(d, e);
  if (with_derivatives) {
    out.dmean_dmu.resize(e, d);
    out.dmean_dsigma.resize(e, d * d);
    out.dcovariance_dmu.resize(e * e, d);
    out.dcovariance_dsigma.resize(e * e, d * d);
    out.dcross_dmu.resize(d * e, d);
    out.dcross_dsigma.resize(d * e, d * d);
  }

  evaluate(mu, sigma, out, with_derivatives);

  bool finite = out.mean.allFinite() && out.covariance.allFinite() && out.cross_covariance.allFinite();
  if (with_derivatives)
    finite = finite && out.dmean_dmu.allFinite() && out.dmean_dsigma.allFinite() &&
             out.dcovariance_dmu.allFinite() && out.dcovariance_dsigma.allFinite() &&
             out.dcross_dmu.allFinite() && out.dcross_dsigma.allFinite();
  if (!finite)
    throw std::invalid_argument(who() + "a moment or derivative overflowed (mu, Sigma or the GP weights are out of range)");
  out.has_derivatives = with_derivatives;
}

}  // namespace gpilqg::gp
