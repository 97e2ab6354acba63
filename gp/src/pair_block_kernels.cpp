#include "pair_block_kernels.hpp"

#include <algorithm>

namespace gpilqg::gp::detail {

namespace {

// The bodies, inlined into one function per instruction set (GCC inlines a function compiled for the
// baseline into one with a wider target, and vectorises the inlined loops for that target).

// Four terms per pass over a column: each pass loads and stores the column once for four
// multiply-adds, not once per multiply-add.

[[gnu::always_inline]] inline void form_exponents_body(const ExponentBlock& e) {
  for (Eigen::Index c = 0; c < e.cols; ++c) {
    double* __restrict out = e.block + c * e.rows;
    const double* __restrict row = e.row_term;
    const double shift = e.col_term[c];
    for (Eigen::Index i = 0; i < e.rows; ++i) out[i] = row[i] + shift;
    Eigen::Index k = 0;
    for (; k + 4 <= e.d; k += 4) {
      const double s0 = e.rhs[c + k * e.rhs_stride], s1 = e.rhs[c + (k + 1) * e.rhs_stride];
      const double s2 = e.rhs[c + (k + 2) * e.rhs_stride], s3 = e.rhs[c + (k + 3) * e.rhs_stride];
      const double* __restrict l0 = e.lhs + k * e.lhs_stride;
      const double* __restrict l1 = l0 + e.lhs_stride;
      const double* __restrict l2 = l1 + e.lhs_stride;
      const double* __restrict l3 = l2 + e.lhs_stride;
      for (Eigen::Index i = 0; i < e.rows; ++i) out[i] += ((l0[i] * s0 + l1[i] * s1) + (l2[i] * s2 + l3[i] * s3));
    }
    for (; k < e.d; ++k) {
      const double s = e.rhs[c + k * e.rhs_stride];
      const double* __restrict l = e.lhs + k * e.lhs_stride;
      for (Eigen::Index i = 0; i < e.rows; ++i) out[i] += l[i] * s;
    }
    const double cap = e.cap;
    for (Eigen::Index i = 0; i < e.rows; ++i) out[i] = std::min(out[i], cap);
  }
}

[[gnu::always_inline]] inline void accumulate_block_body(const BlockUpdate& u) {
  for (Eigen::Index k = 0; k < u.d; ++k) {
    double* __restrict out = u.out + k * u.out_stride;
    const double* v = u.v + k * u.v_stride;
    Eigen::Index c = 0;
    for (; c + 4 <= u.cols; c += 4) {
      const double s0 = v[c], s1 = v[c + 1], s2 = v[c + 2], s3 = v[c + 3];
      const double* __restrict b0 = u.block + c * u.rows;
      const double* __restrict b1 = b0 + u.rows;
      const double* __restrict b2 = b1 + u.rows;
      const double* __restrict b3 = b2 + u.rows;
      for (Eigen::Index i = 0; i < u.rows; ++i) out[i] += ((b0[i] * s0 + b1[i] * s1) + (b2[i] * s2 + b3[i] * s3));
    }
    for (; c < u.cols; ++c) {
      const double s = v[c];
      const double* __restrict b = u.block + c * u.rows;
      for (Eigen::Index i = 0; i < u.rows; ++i) out[i] += b[i] * s;
    }
  }
}

void form_exponents_baseline(const ExponentBlock& e) { form_exponents_body(e); }
void accumulate_block_baseline(const BlockUpdate& u) { accumulate_block_body(u); }

#if defined(__x86_64__)
[[gnu::target("avx2,fma")]] void form_exponents_avx2(const ExponentBlock& e) { form_exponents_body(e); }
[[gnu::target("avx2,fma")]] void accumulate_block_avx2(const BlockUpdate& u) { accumulate_block_body(u); }
[[gnu::target("avx512f,avx2,fma")]] void form_exponents_avx512(const ExponentBlock& e) { form_exponents_body(e); }
[[gnu::target("avx512f,avx2,fma")]] void accumulate_block_avx512(const BlockUpdate& u) { accumulate_block_body(u); }
#endif

}  // namespace

void form_exponents(const ExponentBlock& e, VectorIsa isa) {
  require_supported(isa, "form_exponents");
  switch (isa) {
#if defined(__x86_64__)
    case VectorIsa::Avx512: form_exponents_avx512(e); return;
    case VectorIsa::Avx2: form_exponents_avx2(e); return;
#endif
    default: form_exponents_baseline(e); return;
  }
}

void form_exponents(const ExponentBlock& e) { form_exponents(e, widest_supported_isa()); }

void accumulate_block(const BlockUpdate& u, VectorIsa isa) {
  require_supported(isa, "accumulate_block");
  switch (isa) {
#if defined(__x86_64__)
    case VectorIsa::Avx512: accumulate_block_avx512(u); return;
    case VectorIsa::Avx2: accumulate_block_avx2(u); return;
#endif
    default: accumulate_block_baseline(u); return;
  }
}

void accumulate_block(const BlockUpdate& u) { accumulate_block(u, widest_supported_isa()); }

}  // namespace gpilqg::gp::detail
