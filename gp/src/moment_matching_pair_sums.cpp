#include "moment_matching_pair_sums.hpp"

#include <algorithm>

#include "blas_lapack.hpp"
#include "pair_block_kernels.hpp"
#include "moment_matching_internal.hpp"
#include "vector_expm1.hpp"

namespace gpilqg::gp::detail {

namespace {

/// Columns per block: 64 columns of N = 600 rows are 300 KiB, within a core's second-level cache.
constexpr Eigen::Index kPairBlock = 64;

/// D_ij is capped here before expm1: D_ij > 700 needs max(q_ai, q_bj) < sf^2 e^-700, so Q_ij (<= sf_a^2
/// sf_b^2 e^-700) is negligible, and the cap keeps q_ai q_bj expm1(D_ij) from becoming 0 * inf.
constexpr double kMaxLogRatio = 700.0;

}  // namespace

PairSums pair_sums(const PairTerms& in, bool subtract_kinv, bool derivatives, MomentMatchWorkerScratch& w) {
  const bool symmetric = in.kinv != nullptr;
  const Eigen::Index n_a = in.cross_lhs.rows();
  const Eigen::Index n_b = in.cross_rhs.rows();
  const Eigen::Index d = in.cross_lhs.cols();
  auto row_sums = view(w.row_sums, n_a);
  auto col_sums = view(w.col_sums, n_b);
  auto omega_v = view(w.omega_v, n_a, d);
  if (derivatives) {
    row_sums.setZero();
    omega_v.setZero();
  }
  const double kinv_weight = subtract_kinv ? 1.0 : 0.0;
  PairSums sums;
  for (Eigen::Index j0 = 0; j0 < n_b; j0 += kPairBlock) {
    const Eigen::Index nb = std::min(kPairBlock, n_b - j0);
    const Eigen::Index r0 = symmetric ? j0 : 0;        // the block's first row
    const Eigen::Index nr = n_a - r0;
    const Eigen::Index once = symmetric ? nb : nr;     // rows counted once; the rest (below) twice
    const Eigen::Index twice = nr - once;
    auto block = view(w.nn, nr, nb);
    form_exponents({in.cross_lhs.data() + r0, in.cross_lhs.outerStride(), in.cross_rhs.data() + j0,
                    in.cross_rhs.outerStride(), d, in.row_term.data() + r0, in.col_term.data() + j0, kMaxLogRatio,
                    nr, nb, block.data()});
    expm1_in_place({block.data(), static_cast<std::size_t>(nr * nb)});

    const auto gamma_rows = in.gamma_a.segment(r0, nr);
    for (Eigen::Index c = 0; c < nb; ++c) {
      const Eigen::Index j = j0 + c;
      auto e = block.col(c);
      if (!symmetric) {
        // Omega = gamma_a gamma_b' .* E; the column sum is formed the same way with and without
        // derivatives, so that the covariance does not depend on whether they are asked for.
        const double column = in.gamma_b(j) * (e.array() * gamma_rows.array()).sum();
        sums.total += column;
        if (!derivatives) continue;
        e = e.cwiseProduct(gamma_rows) * in.gamma_b(j);
        col_sums(j) = column;
        row_sums += e;
        continue;
      }
      const auto kinv = in.kinv->col(j).segment(r0, nr).array();
      const auto q = in.kernel_mean->segment(r0, nr).array();
      const double q_j = (*in.kernel_mean)(j);
      const auto weighted = e.array() * gamma_rows.array();
      const auto kinv_weighted = e.array() * kinv * q;
      sums.centred += in.gamma_b(j) * (weighted.head(once).sum() + 2.0 * weighted.tail(twice).sum());
      sums.kinv_centred += q_j * (kinv_weighted.head(once).sum() + 2.0 * kinv_weighted.tail(twice).sum());
      if (!derivatives) continue;
      // Omega = gamma gamma' .* E - (E + 1) .* Kinv .* q q' (the second term dropped when clamped)
      e = (in.gamma_b(j) * weighted - (kinv_weight * q_j) * (e.array() + 1.0) * kinv * q).matrix();
      const double once_sum = e.head(once).sum();
      const double twice_sum = e.tail(twice).sum();
      sums.total += once_sum + 2.0 * twice_sum;
      row_sums.segment(r0, nr) += e;
      row_sums(j) += twice_sum;  // the mirror image of the rows below the diagonal block
    }
    if (!derivatives) continue;
    accumulate_block({block.data(), nr, nb, in.centred_b.data() + j0, in.centred_b.outerStride(), d,
                      omega_v.data() + r0, n_a});
    if (symmetric && twice > 0)  // the mirror image: Omega(J, below) V(below) = Omega(below, J)' V(below)
      blas::multiply(1.0, block.bottomRows(twice), blas::Transpose::Yes, in.centred_b.middleRows(j0 + nb, twice),
                     blas::Transpose::No, 1.0, omega_v.middleRows(j0, nb));
  }
  if (derivatives && symmetric) col_sums = row_sums;
  return sums;
}

}  // namespace gpilqg::gp::detail
