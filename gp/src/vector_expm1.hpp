/// @file vector_expm1.hpp
/// expm1(x) = e^x - 1 over an array, several lanes per instruction.
///
/// Exact moment matching evaluates expm1 once per pair of training points and pair of outputs
/// (moment_matching_covariance.cpp): millions per belief step, where one scalar glibc call costs about
/// 7 ns. glibc's vector math library (libmvec, glibc >= 2.35, linked through libm) has expm1 for 2, 4
/// and 8 doubles per call, named by the x86-64 vector function ABI: _ZGVbN2v_expm1 (SSE2, SSE4.1 when
/// present), _ZGVdN4v_expm1 (AVX2 + FMA) and _ZGVeN8v_expm1 (AVX-512), each within 4 ulp of the exact
/// value. The widest kind the processor supports is chosen at run time (vector_isa.hpp), so a Debian
/// build for baseline x86-64 uses AVX2 or AVX-512 where the processor has them and stays correct on
/// every x86-64 processor. Elsewhere (another architecture or an older glibc) it is a loop over
/// std::expm1.
#pragma once

#include <span>

#include "vector_isa.hpp"

namespace gpilqg::gp::detail {

/// values[i] = expm1(values[i]) for every i, with the widest supported kind (vector_isa.hpp).
void expm1_in_place(std::span<double> values);

/// The same with a given kind (tests and benchmarks compare the kinds); throws std::invalid_argument
/// when the kind is not supported here.
void expm1_in_place(std::span<double> values, VectorIsa isa);

}  // namespace gpilqg::gp::detail
