#pragma once
/// @file blas_library.hpp
/// Which BLAS the GP backends run on (docs/building.md#blas), for reports: the file the dynamic
/// loader resolved, and OpenBLAS's build and the kernels it chose for this CPU when it is OpenBLAS,
/// e.g. "/usr/lib/x86_64-linux-gnu/openblas-pthread/libblas.so.3 (OpenBLAS 0.3.21 DYNAMIC_ARCH
/// NO_AFFINITY SkylakeX MAX_THREADS=64, core SkylakeX)".

#include <string>

namespace gpilqg::gp {

std::string blas_library();

}  // namespace gpilqg::gp
