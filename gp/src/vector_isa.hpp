#pragma once
/// @file vector_isa.hpp
/// The x86-64 vector instruction sets the GP's innermost loops choose between at run time
/// (vector_expm1.hpp, pair_block_kernels.hpp). Debian builds for baseline x86-64 (SSE2); the loops
/// are compiled once more for AVX2 + FMA and for AVX-512 (GCC's target attribute), and the widest
/// kind the processor supports (__builtin_cpu_supports) is chosen once per process. Elsewhere (another
/// architecture) only the plain kind exists.

#include <string_view>

namespace gpilqg::gp::detail {

/// Narrowest first. Scalar: no vector code of our own (a plain loop as the compiler makes it);
/// Sse2: the x86-64 baseline.
enum class VectorIsa { Scalar, Sse2, Avx2, Avx512 };

/// "scalar", "sse2", "avx2" or "avx512" (benchmark labels, messages).
std::string_view to_string(VectorIsa isa);

/// The widest kind this build has and this processor runs (AVX2 needs FMA too).
VectorIsa widest_supported_isa();

/// True when this build has the kind and this processor can run it (Scalar always can).
bool supported(VectorIsa isa);

/// Throws std::invalid_argument naming `who`, the kind and the widest supported one, unless supported.
void require_supported(VectorIsa isa, std::string_view who);

}  // namespace gpilqg::gp::detail
