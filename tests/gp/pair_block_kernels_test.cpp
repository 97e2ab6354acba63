/// detail::form_exponents and detail::accumulate_block (gp/src/pair_block_kernels.hpp) for every
/// instruction set this build and processor support, against the same products written with Eigen,
/// on blocks cut out of larger matrices (leading dimensions larger than the block) and with sizes
/// that leave remainders in every loop (D = 5 and 7, 13 columns, 37 rows).

#include <gtest/gtest.h>

#include <random>

#include "../../gp/src/pair_block_kernels.hpp"
#include "gpilqg/core/types.hpp"
#include "test_support.hpp"

namespace gpilqg::gp::detail {
namespace {

Matrix random_matrix(Eigen::Index rows, Eigen::Index cols, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix m(rows, cols);
  for (Eigen::Index j = 0; j < cols; ++j)
    for (Eigen::Index i = 0; i < rows; ++i) m(i, j) = u(gen);
  return m;
}

TEST(PairBlockKernels, EveryInstructionSetMatchesTheEigenProducts) {
  for (const Eigen::Index d : {5, 7}) {
    const Matrix lhs_full = random_matrix(50, d, 1);    // rows 4..40 are L (37 rows, leading dimension 50)
    const Matrix rhs_full = random_matrix(30, d, 2);    // rows 9..21 are R (13 rows, leading dimension 30)
    const Matrix v_full = random_matrix(30, d, 3);
    const Vector row_term = ::gpilqg::test::random_vector(37, -1.0, 1.0, 4);
    const Vector col_term = ::gpilqg::test::random_vector(13, -1.0, 1.0, 5);
    const auto lhs = lhs_full.middleRows(4, 37);
    const auto rhs = rhs_full.middleRows(9, 13);
    const double cap = 0.8;  // some entries capped
    Matrix expected = (lhs * rhs.transpose()).colwise() + row_term;
    expected.rowwise() += col_term.transpose();
    expected = expected.cwiseMin(cap);
    const Matrix out0 = random_matrix(40, d, 6);  // rows 2..38 are O (leading dimension 40)
    Matrix expected_out = out0;
    expected_out.middleRows(2, 37) += expected * v_full.middleRows(9, 13);

    int kinds = 0;
    for (VectorIsa isa : {VectorIsa::Scalar, VectorIsa::Sse2, VectorIsa::Avx2, VectorIsa::Avx512}) {
      if (!supported(isa)) continue;
      ++kinds;
      Matrix block(37, 13);
      form_exponents({lhs_full.data() + 4, lhs_full.outerStride(), rhs_full.data() + 9, rhs_full.outerStride(), d,
                      row_term.data(), col_term.data(), cap, 37, 13, block.data()},
                     isa);
      EXPECT_LE((block - expected).cwiseAbs().maxCoeff(), 1e-14) << to_string(isa) << ", D = " << d;
      EXPECT_EQ(block.maxCoeff(), cap) << to_string(isa);
      Matrix out = out0;
      accumulate_block({expected.data(), 37, 13, v_full.data() + 9, v_full.outerStride(), d, out.data() + 2, 40}, isa);
      EXPECT_LE((out - expected_out).cwiseAbs().maxCoeff(), 1e-13) << to_string(isa) << ", D = " << d;
      EXPECT_EQ(out.topRows(2), out0.topRows(2)) << "rows outside the block are untouched";
      EXPECT_EQ(out.bottomRows(1), out0.bottomRows(1));
    }
    EXPECT_GE(kinds, 1);
  }
}

}  // namespace
}  // namespace gpilqg::gp::detail
