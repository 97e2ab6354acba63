// Compiles gpilqg_policy.hpp as C++17 with the standard library only (evaluator/CMakeLists.txt).
#include "gpilqg_policy.hpp"

namespace {
[[maybe_unused]] gpilqg::evaluator::Status one_step(const gpilqg::evaluator::AffinePolicy& policy, const double* x,
                                                    double* u) {
  return policy.control(0, x, u);
}
}  // namespace
