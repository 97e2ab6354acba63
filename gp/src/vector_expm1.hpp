/// @file vector_expm1.hpp
/// expm1(x) = e^x - 1 over an array, several lanes per instruction.
///
/// Exact moment matching evaluates expm1 once per pair of training points and pair of outputs
/// (moment_matching_covariance.cpp): millions per belief step, where one scalar glibc call costs about
/// 7 ns. glibc's vector math library (libmvec, glibc >= 2.35, linked through libm) has expm1 for 2, 4
/// and 8 doubles per call, named by the x86-64 vector function ABI: _ZGVbN2v_expm1 (SSE2, SSE4.1 when
/// present), _ZGVdN4v_expm1 (AVX2 + FMA) and _ZGVeN8v_expm1 (AVX-512), each within 4 ulp of the exact
/// value. The widest kind the processor supports is chosen once, at run time
/// (__builtin_cpu_supports), so a Debian build for baseline x86-64 uses AVX2 or AVX-512 where the
/// processor has them and stays correct on every x86-64 processor. Elsewhere (another architecture or
/// an older glibc) it is a loop over std::expm1.
#pragma once

#include <span>
#include <string_view>

namespace gpilqg::gp::detail {

/// The instruction sets expm1_in_place can use, narrowest first.
enum class VectorIsa { Scalar, Sse2, Avx2, Avx512 };

/// "scalar", "sse2", "avx2" or "avx512" (benchmark labels).
std::string_view to_string(VectorIsa isa);

/// True when this build has the kind and this processor can run it (Scalar always can).
bool supported(VectorIsa isa);

/// The widest supported kind; what expm1_in_place(values) uses.
VectorIsa widest_supported_isa();

/// values[i] = expm1(values[i]) for every i, with the widest supported kind.
void expm1_in_place(std::span<double> values);

/// The same with a given kind (tests and benchmarks compare the kinds); throws std::invalid_argument
/// when the kind is not supported here.
void expm1_in_place(std::span<double> values, VectorIsa isa);

}  // namespace gpilqg::gp::detail
