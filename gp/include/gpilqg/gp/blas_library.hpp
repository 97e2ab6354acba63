#pragma once
/// @file blas_library.hpp
/// Which BLAS the GP backends run on (docs/building.md#blas), for reports: the file the dynamic
/// loader resolved, and OpenBLAS's build and the kernels it chose for this CPU when it is OpenBLAS,
/// e.g. "/usr/lib/x86_64-linux-gnu/openblas-pthread/libblas.so.3 (OpenBLAS 0.3.21 DYNAMIC_ARCH
/// NO_AFFINITY SkylakeX MAX_THREADS=64, core SkylakeX)".

#include <optional>
#include <string>

namespace gpilqg::gp {

std::string blas_library();

/// The value of OPENBLAS_CORETYPE that gives OpenBLAS the kernels this processor can run, when the
/// process runs on OpenBLAS with kernels of an older processor; nullopt otherwise (another BLAS, a
/// good choice already, or OPENBLAS_CORETYPE already set).
///
/// OpenBLAS chooses its kernels once, when it loads, from the processor's model number. A model it
/// does not know (e.g. a newer Xeon, as OpenBLAS 0.3.21 in Debian 12 sees it) falls back to its
/// "Prescott" kernels (SSE3): dgemm then runs at a fifth of the rate of its AVX-512 kernels on the same
/// processor. The answer is "SkylakeX" when the processor has AVX-512 F, CD, BW, DQ and VL, "Haswell"
/// when it has AVX2 and FMA, and nullopt when OpenBLAS already uses one of its AVX2 or AVX-512 kernel
/// sets. Since the choice is made at load time, only a new process can use it: the gpilqg program
/// starts itself again with the variable set (docs/building.md#blas).
std::optional<std::string> better_openblas_coretype();

}  // namespace gpilqg::gp
