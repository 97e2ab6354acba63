// gpilqg_policy.hpp: run a gpilqg policy file on a robot's controller, in C++17 with the standard
// library only (header-only; no Eigen, no HDF5, no gpilqg library).
//
// The arrays are the datasets of the policy file
// (docs/formats.md#policy-file-gpilqg-plan---out-policyh5) in the order HDF5 stores them (row-major):
// x_bar (T+1) x n, u_bar T x m, K T x m x n, and the attributes u_min and u_max (m entries each, or
// empty when the file has none). The control law at step t with the measured state x is
//     u = clamp(u_bar_t + K_t (x - x_bar_t), u_min, u_max).
// Construction checks the sizes once (and may allocate); control() never allocates or throws.
#pragma once

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace gpilqg::evaluator {

enum class Status {
  ok,
  time_out_of_range,  ///< t < 0 or t >= horizon(): the plan has no control there
  non_finite_state,   ///< x holds a NaN or an infinity
};

class AffinePolicy {
 public:
  /// Throws std::invalid_argument naming the array whose size does not match (horizon, n, m).
  AffinePolicy(int horizon, int n, int m, std::vector<double> x_bar, std::vector<double> u_bar, std::vector<double> K,
               std::vector<double> u_min = {}, std::vector<double> u_max = {})
      : T_(horizon), n_(n), m_(m), x_bar_(std::move(x_bar)), u_bar_(std::move(u_bar)), K_(std::move(K)),
        u_min_(std::move(u_min)), u_max_(std::move(u_max)) {
    if (T_ < 1 || n_ < 1 || m_ < 1) throw std::invalid_argument("gpilqg policy: horizon, n and m must be >= 1");
    expect("x_bar", x_bar_.size(), size(T_ + 1) * size(n_));
    expect("u_bar", u_bar_.size(), size(T_) * size(m_));
    expect("K", K_.size(), size(T_) * size(m_) * size(n_));
    if (!u_min_.empty()) expect("u_min", u_min_.size(), size(m_));
    if (!u_max_.empty()) expect("u_max", u_max_.size(), size(m_));
  }

  int horizon() const noexcept { return T_; }
  int state_dim() const noexcept { return n_; }
  int control_dim() const noexcept { return m_; }

  /// Writes the control of step t for the measured state x (n entries) into u (m entries); on any
  /// status other than ok, u is left untouched.
  Status control(int t, const double* x, double* u) const noexcept {
    if (t < 0 || t >= T_) return Status::time_out_of_range;
    for (int i = 0; i < n_; ++i)
      if (!std::isfinite(x[i])) return Status::non_finite_state;
    const double* x_bar = x_bar_.data() + size(t) * size(n_);
    for (int j = 0; j < m_; ++j) {
      double v = u_bar_[size(t) * size(m_) + size(j)];
      const double* gain = K_.data() + (size(t) * size(m_) + size(j)) * size(n_);
      for (int i = 0; i < n_; ++i) v += (x[i] - x_bar[i]) * gain[i];
      if (!u_min_.empty() && v < u_min_[size(j)]) v = u_min_[size(j)];
      if (!u_max_.empty() && v > u_max_[size(j)]) v = u_max_[size(j)];
      u[j] = v;
    }
    return Status::ok;
  }

 private:
  static std::size_t size(int v) { return static_cast<std::size_t>(v); }
  static void expect(const char* name, std::size_t found, std::size_t expected) {
    if (found != expected)
      throw std::invalid_argument(std::string("gpilqg policy: ") + name + " has " + std::to_string(found) +
                                  " entries; expected " + std::to_string(expected));
  }
  int T_, n_, m_;
  std::vector<double> x_bar_, u_bar_, K_, u_min_, u_max_;
};

}  // namespace gpilqg::evaluator
