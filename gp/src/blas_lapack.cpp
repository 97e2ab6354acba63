#include "blas_lapack.hpp"
#include "gpilqg/gp/blas_library.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <cstddef>
#include <filesystem>
#include <stdexcept>

// The Fortran interface of BLAS and LAPACK (LP64: 32-bit integers, Debian's libblas3/liblapack3 and
// libopenblas0). gfortran passes the length of each character argument as a trailing size_t.
extern "C" {
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info, std::size_t);
void dtrtri_(const char* uplo, const char* diag, const int* n, double* a, const int* lda, int* info, std::size_t,
             std::size_t);
void dlauum_(const char* uplo, const int* n, double* a, const int* lda, int* info, std::size_t);
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb, std::size_t, std::size_t,
            std::size_t, std::size_t);
void dtrmm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb, std::size_t, std::size_t,
            std::size_t, std::size_t);
void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha, const double* a,
            const int* lda, const double* beta, double* c, const int* ldc, std::size_t, std::size_t);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
            const int* ldc, std::size_t, std::size_t);
}

namespace gpilqg::gp::detail::blas {

namespace {

/// A dimension as BLAS's 32-bit integer; larger matrices (2^31 rows) are refused, never truncated.
int as_int(Eigen::Index value) {
  if (value > INT_MAX) throw std::length_error("a dense GP matrix dimension exceeds the BLAS's 32-bit index range");
  return static_cast<int>(value);
}

/// Leading dimension: at least 1 even for an empty block (the reference BLAS checks lda >= max(1, m)).
int leading(Eigen::Index outer_stride, Eigen::Index rows) {
  return as_int(std::max<Eigen::Index>({outer_stride, rows, 1}));
}

/// OpenBLAS's threaded build (Debian's default, libopenblas0-pthread) would start its own threads
/// inside the project's; it runs every call on the calling thread once told to use one thread. (Its
/// serial build is not safe to call from several threads at once: Debian builds it without
/// USE_LOCKING, and concurrent GP fits gave different bits from run to run.) Done when this library
/// is loaded, before CHOLMOD or anything else calls the BLAS. Other BLAS libraries run on the calling
/// thread unless told otherwise (docs/building.md#blas).
const bool kSingleThreadedAtLoad = [] {
  using SetThreads = void (*)(int);
  if (auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) set(1);
  return true;
}();

char side_flag(Side s) { return s == Side::Left ? 'L' : 'R'; }
char transpose_flag(Transpose t) { return t == Transpose::No ? 'N' : 'T'; }

}  // namespace

bool cholesky_lower(Eigen::Ref<Matrix> a) {
  const int n = as_int(a.rows());
  if (n == 0) return true;
  const int lda = leading(a.outerStride(), a.rows());
  int info = 0;
  dpotrf_("L", &n, a.data(), &lda, &info, 1);
  if (info != 0) return false;
  const auto diagonal = a.diagonal().array();
  return diagonal.allFinite() && (diagonal > 0.0).all();
}

void invert_lower(Eigen::Ref<Matrix> l) {
  const int n = as_int(l.rows());
  if (n == 0) return;
  const int lda = leading(l.outerStride(), l.rows());
  int info = 0;
  dtrtri_("L", "N", &n, l.data(), &lda, &info, 1, 1);
  if (info != 0) throw std::logic_error("invert_lower: singular triangular factor (a Cholesky factor never is)");
}

void lower_gram(Eigen::Ref<Matrix> m) {
  const int n = as_int(m.rows());
  if (n == 0) return;
  const int lda = leading(m.outerStride(), m.rows());
  int info = 0;
  dlauum_("L", &n, m.data(), &lda, &info, 1);
}

namespace {

using TriangularRoutine = void (*)(const char*, const char*, const char*, const char*, const int*, const int*,
                                   const double*, const double*, const int*, double*, const int*, std::size_t,
                                   std::size_t, std::size_t, std::size_t);

void triangular(TriangularRoutine routine, Side side, Transpose transpose, const Eigen::Ref<const Matrix>& l,
                Eigen::Ref<Matrix> b) {
  const int m = as_int(b.rows()), n = as_int(b.cols());
  if (m == 0 || n == 0) return;
  const Eigen::Index order = side == Side::Left ? b.rows() : b.cols();
  if (l.rows() != order || l.cols() != order) throw std::logic_error("blas: triangular factor of the wrong size");
  const int lda = leading(l.outerStride(), l.rows()), ldb = leading(b.outerStride(), b.rows());
  const char s = side_flag(side), t = transpose_flag(transpose);
  const double one = 1.0;
  routine(&s, "L", &t, "N", &m, &n, &one, l.data(), &lda, b.data(), &ldb, 1, 1, 1, 1);
}

}  // namespace

void solve_lower(Side side, Transpose transpose, const Eigen::Ref<const Matrix>& l, Eigen::Ref<Matrix> b) {
  triangular(&dtrsm_, side, transpose, l, b);
}

void multiply_lower(Side side, Transpose transpose, const Eigen::Ref<const Matrix>& l, Eigen::Ref<Matrix> b) {
  triangular(&dtrmm_, side, transpose, l, b);
}

void rank_update_lower(double alpha, const Eigen::Ref<const Matrix>& a, Transpose transpose, double beta,
                       Eigen::Ref<Matrix> c) {
  const Eigen::Index order = transpose == Transpose::No ? a.rows() : a.cols();
  const int n = as_int(c.rows()), k = as_int(transpose == Transpose::No ? a.cols() : a.rows());
  if (order != c.rows() || c.cols() != c.rows()) throw std::logic_error("blas: rank update of the wrong size");
  if (n == 0) return;
  const int lda = leading(a.outerStride(), a.rows()), ldc = leading(c.outerStride(), c.rows());
  const char t = transpose_flag(transpose);
  dsyrk_("L", &t, &n, &k, &alpha, a.data(), &lda, &beta, c.data(), &ldc, 1, 1);
}

void multiply(double alpha, const Eigen::Ref<const Matrix>& a, Transpose transpose_a, const Eigen::Ref<const Matrix>& b,
              Transpose transpose_b, double beta, Eigen::Ref<Matrix> c) {
  const Eigen::Index k = transpose_a == Transpose::No ? a.cols() : a.rows();
  const Eigen::Index rows = transpose_a == Transpose::No ? a.rows() : a.cols();
  const Eigen::Index cols = transpose_b == Transpose::No ? b.cols() : b.rows();
  const Eigen::Index k_b = transpose_b == Transpose::No ? b.rows() : b.cols();
  if (rows != c.rows() || cols != c.cols() || k != k_b) throw std::logic_error("blas: product of the wrong sizes");
  if (c.size() == 0) return;
  const int m = as_int(rows), n = as_int(cols), kk = as_int(k);
  const int lda = leading(a.outerStride(), a.rows()), ldb = leading(b.outerStride(), b.rows());
  const int ldc = leading(c.outerStride(), c.rows());
  const char ta = transpose_flag(transpose_a), tb = transpose_flag(transpose_b);
  dgemm_(&ta, &tb, &m, &n, &kk, &alpha, a.data(), &lda, b.data(), &ldb, &beta, c.data(), &ldc, 1, 1);
}

std::string library_description() {
  Dl_info info{};
  std::string text = "unknown BLAS";
  if (dladdr(reinterpret_cast<void*>(&dgemm_), &info) != 0 && info.dli_fname != nullptr) {
    std::error_code error;  // the alternatives' symlinks resolved: which implementation it is
    const std::filesystem::path file = std::filesystem::canonical(info.dli_fname, error);
    text = error ? std::string(info.dli_fname) : file.string();
  }
  using Config = const char* (*)();
  using CoreName = const char* (*)();
  if (auto config = reinterpret_cast<Config>(dlsym(RTLD_DEFAULT, "openblas_get_config"))) {
    text += std::string(" (") + config();
    if (auto core = reinterpret_cast<CoreName>(dlsym(RTLD_DEFAULT, "openblas_get_corename"))) text += std::string(", core ") + core();
    text += ")";
  }
  return text;
}

}  // namespace gpilqg::gp::detail::blas

namespace gpilqg::gp {

std::string blas_library() { return detail::blas::library_description(); }

std::optional<std::string> better_openblas_coretype() {
#if defined(__x86_64__)
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) return std::nullopt;
  using CoreName = const char* (*)();
  const auto core_name = reinterpret_cast<CoreName>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  if (core_name == nullptr) return std::nullopt;  // not OpenBLAS
  const std::string core = core_name();
  // OpenBLAS's x86-64 kernel sets that use AVX2 or AVX-512 (its names as openblas_get_corename spells them).
  for (const char* wide : {"Haswell", "Zen", "SkylakeX", "Cooperlake", "SapphireRapids", "Excavator"})
    if (core == wide) return std::nullopt;
  __builtin_cpu_init();
  const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
                      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
                      __builtin_cpu_supports("avx512vl");
  if (avx512) return "SkylakeX";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "Haswell";
#endif
  return std::nullopt;
}

}  // namespace gpilqg::gp
