#include "vector_isa.hpp"

#include <stdexcept>
#include <string>

namespace gpilqg::gp::detail {

namespace {

VectorIsa detect_widest() {
#if defined(__x86_64__)
  __builtin_cpu_init();
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (avx2 && __builtin_cpu_supports("avx512f")) return VectorIsa::Avx512;
  if (avx2) return VectorIsa::Avx2;
  return VectorIsa::Sse2;  // part of every x86-64 processor
#else
  return VectorIsa::Scalar;
#endif
}

}  // namespace

std::string_view to_string(VectorIsa isa) {
  switch (isa) {
    case VectorIsa::Scalar: return "scalar";
    case VectorIsa::Sse2: return "sse2";
    case VectorIsa::Avx2: return "avx2";
    case VectorIsa::Avx512: return "avx512";
  }
  return "unknown";
}

VectorIsa widest_supported_isa() {
  static const VectorIsa widest = detect_widest();
  return widest;
}

bool supported(VectorIsa isa) { return static_cast<int>(isa) <= static_cast<int>(widest_supported_isa()); }

void require_supported(VectorIsa isa, std::string_view who) {
  if (!supported(isa))
    throw std::invalid_argument(std::string(who) + ": instruction set '" + std::string(to_string(isa)) +
                                "' is not supported by this build or processor; the widest supported is '" +
                                std::string(to_string(widest_supported_isa())) + "'");
}

}  // namespace gpilqg::gp::detail
