#include "vector_expm1.hpp"

#include <cmath>
#include <cstddef>

#if defined(__x86_64__) && defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 35))
#define GPILQG_HAVE_LIBMVEC_EXPM1 1
#include <immintrin.h>

// libmvec's entry points (x86-64 vector function ABI: b = SSE, d = AVX2, e = AVX-512; N2/N4/N8 lanes,
// v = one vector argument). glibc declares them only under -ffast-math, so they are declared here. Each
// is an indirect function that glibc resolves to the best implementation of its kind.
extern "C" {
__m128d _ZGVbN2v_expm1(__m128d);
__attribute__((target("avx2,fma"))) __m256d _ZGVdN4v_expm1(__m256d);
__attribute__((target("avx512f"))) __m512d _ZGVeN8v_expm1(__m512d);
}
#endif

namespace gpilqg::gp::detail {

namespace {

void scalar_expm1(double* x, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) x[i] = std::expm1(x[i]);
}

#ifdef GPILQG_HAVE_LIBMVEC_EXPM1

void sse2_expm1(double* x, std::size_t n) {
  std::size_t i = 0;
  for (; i + 2 <= n; i += 2) _mm_storeu_pd(x + i, _ZGVbN2v_expm1(_mm_loadu_pd(x + i)));
  scalar_expm1(x + i, n - i);
}

__attribute__((target("avx2,fma"))) void avx2_expm1(double* x, std::size_t n) {
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) _mm256_storeu_pd(x + i, _ZGVdN4v_expm1(_mm256_loadu_pd(x + i)));
  scalar_expm1(x + i, n - i);
}

__attribute__((target("avx512f"))) void avx512_expm1(double* x, std::size_t n) {
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) _mm512_storeu_pd(x + i, _ZGVeN8v_expm1(_mm512_loadu_pd(x + i)));
  scalar_expm1(x + i, n - i);
}

#endif

}  // namespace

void expm1_in_place(std::span<double> values, VectorIsa isa) {
  require_supported(isa, "expm1_in_place");
  double* x = values.data();
  const std::size_t n = values.size();
  switch (isa) {
#ifdef GPILQG_HAVE_LIBMVEC_EXPM1
    case VectorIsa::Avx512: avx512_expm1(x, n); return;
    case VectorIsa::Avx2: avx2_expm1(x, n); return;
    case VectorIsa::Sse2: sse2_expm1(x, n); return;
#endif
    default: scalar_expm1(x, n); return;
  }
}

void expm1_in_place(std::span<double> values) { expm1_in_place(values, widest_supported_isa()); }

}  // namespace gpilqg::gp::detail
