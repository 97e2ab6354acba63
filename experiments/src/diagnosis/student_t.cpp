#include "gpilqg/experiments/diagnosis/student_t.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>

namespace gpilqg::diagnosis {

namespace {

void check_batches(int batches) {
  if (batches < 2)
    throw std::invalid_argument("batch statistics: " + std::to_string(batches) + " batch(es); expected at least 2");
}

}  // namespace

double student_t_quantile(double p, double dof) {
  if (!(dof >= 1.0)) throw std::invalid_argument("Student's t: degrees of freedom " + std::to_string(dof) + "; expected >= 1");
  if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("Student's t: probability " + std::to_string(p) + "; expected a value in (0, 1)");
  return boost::math::quantile(boost::math::students_t_distribution<double>(dof), p);
}

double batch_half_width(double se, int batches) {
  check_batches(batches);
  return student_t_quantile(0.975, batches - 1.0) * se;
}

double normal_equivalent(double t, int batches) {
  check_batches(batches);
  if (std::isnan(t) || std::isinf(t)) return t;
  constexpr double kCap = 37.0;  // Phi(-37) ~ 6e-300: beyond it the tail is not a double
  const boost::math::students_t_distribution<double> student(batches - 1.0);
  // The smaller tail, for accuracy: z = -Phi^-1(Q(|t|)) with the sign of t.
  const double tail = boost::math::cdf(boost::math::complement(student, std::abs(t)));
  if (!(tail > 0.0)) return std::copysign(kCap, t);
  const double z = -boost::math::quantile(boost::math::normal_distribution<double>(), std::min(tail, 0.5));
  return std::copysign(std::min(z, kCap), t);
}

}  // namespace gpilqg::diagnosis
