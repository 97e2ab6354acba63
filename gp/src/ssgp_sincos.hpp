#pragma once
/// @file ssgp_sincos.hpp
/// Internal: cos and sin of many arguments at once, written so that the compiler vectorises the loop
/// (plain double arithmetic, no branches, no library calls). SSGP evaluates N x m of them per NLML,
/// and glibc's scalar sincos was a fifth of its cost.
///
/// Method (Cody & Waite range reduction, then Taylor polynomials):
///   k = nearest integer to z * 2/pi (the 1.5 * 2^52 rounding trick, exact in round-to-nearest),
///   r = ((z - k P1) - k P2) - k P3 with pi/2 = P1 + P2 + P3; P1 and P2 carry 32 significant bits,
///       so k P1 and k P2 are exact for |k| < 2^21, and |r| <= pi/4 (plus rounding);
///   sin r = r - r^3/3! + ... - r^19/19!,  cos r = 1 - r^2/2! + ... + r^20/20!: on |r| <= pi/4 the
///       first omitted terms are below 1e-20 and 1e-22, so the polynomials are exact to rounding;
///   the quadrant q = k mod 4 selects (sin, cos) = (s, c), (c, -s), (-s, -c), (-c, s); the selection
///   multiplies by exact 0/1 and +-1, so it adds no rounding.
/// Arguments with |z| >= 2^20 (never met in practice: |z| = |w . x| / l) fall back to std::sin/cos.
/// The split of pi/2 was computed from pi by Machin's formula to 80 digits.

#include <cmath>

namespace gpilqg::gp::ssgp_detail {

inline constexpr double kTwoOverPi = 0x1.45f306dc9c883p-1;
inline constexpr double kPiOver2Part1 = 0x1.921fb54400000p+0;   // 32 significant bits
inline constexpr double kPiOver2Part2 = 0x1.0b4611a600000p-34;  // 32 significant bits
inline constexpr double kPiOver2Part3 = 0x1.3198a2e037073p-69;  // the rest, rounded
inline constexpr double kRoundMagic = 6755399441055744.0;       // 1.5 * 2^52
inline constexpr double kLargeArgument = 1048576.0;             // 2^20

/// cos(x) into c and sin(x) into s for |x| < 2^20 (see the file comment).
inline void sincos_reduced(double x, double& c, double& s) {
  const double k = (x * kTwoOverPi + kRoundMagic) - kRoundMagic;
  const double r = ((x - k * kPiOver2Part1) - k * kPiOver2Part2) - k * kPiOver2Part3;
  const double r2 = r * r;
  // sin r = r (1 - r^2/(2*3) (1 - r^2/(4*5) (1 - ...))), cos r = 1 - r^2/2 (1 - r^2/(3*4) (...)),
  // with the reciprocals folded into constants (multiplications vectorise; divisions are slow).
  double ps = 1.0 - r2 * (1.0 / (18.0 * 19.0));
  ps = 1.0 - r2 * (1.0 / (16.0 * 17.0)) * ps;
  ps = 1.0 - r2 * (1.0 / (14.0 * 15.0)) * ps;
  ps = 1.0 - r2 * (1.0 / (12.0 * 13.0)) * ps;
  ps = 1.0 - r2 * (1.0 / (10.0 * 11.0)) * ps;
  ps = 1.0 - r2 * (1.0 / (8.0 * 9.0)) * ps;
  ps = 1.0 - r2 * (1.0 / (6.0 * 7.0)) * ps;
  ps = 1.0 - r2 * (1.0 / (4.0 * 5.0)) * ps;
  ps = 1.0 - r2 * (1.0 / (2.0 * 3.0)) * ps;
  const double sr = r * ps;
  double pc = 1.0 - r2 * (1.0 / (19.0 * 20.0));
  pc = 1.0 - r2 * (1.0 / (17.0 * 18.0)) * pc;
  pc = 1.0 - r2 * (1.0 / (15.0 * 16.0)) * pc;
  pc = 1.0 - r2 * (1.0 / (13.0 * 14.0)) * pc;
  pc = 1.0 - r2 * (1.0 / (11.0 * 12.0)) * pc;
  pc = 1.0 - r2 * (1.0 / (9.0 * 10.0)) * pc;
  pc = 1.0 - r2 * (1.0 / (7.0 * 8.0)) * pc;
  pc = 1.0 - r2 * (1.0 / (5.0 * 6.0)) * pc;
  pc = 1.0 - r2 * (1.0 / (3.0 * 4.0)) * pc;
  const double cr = 1.0 - r2 * 0.5 * pc;
  // q = k mod 4 = k - 4 round(k/4 - 3/8); swap = q mod 2; half = q div 2 (exact, branch-free).
  const double q = k - 4.0 * ((k * 0.25 - 0.375 + kRoundMagic) - kRoundMagic);
  const double half = (q * 0.5 - 0.25 + kRoundMagic) - kRoundMagic;
  const double swap = q - 2.0 * half;
  const double sign_s = 1.0 - 2.0 * half;                               // q = 2, 3: negative
  const double sign_c = 1.0 - 2.0 * (half + swap - 2.0 * half * swap);  // q = 1, 2: negative
  s = sign_s * (sr * (1.0 - swap) + cr * swap);
  c = sign_c * (cr * (1.0 - swap) + sr * swap);
}

/// cos(z[i]) into c[i] and sin(z[i]) into s[i] for i < n; z may be the same array as c or s.
inline void sincos_many(const double* z, double* c, double* s, long n) {
  bool large = false;
  for (long i = 0; i < n; ++i) large |= !(std::abs(z[i]) < kLargeArgument);
  if (!large) {
    for (long i = 0; i < n; ++i) {
      double ci, si;
      sincos_reduced(z[i], ci, si);
      c[i] = ci;
      s[i] = si;
    }
    return;
  }
  for (long i = 0; i < n; ++i) {
    const double x = z[i];
    if (std::abs(x) < kLargeArgument) {
      sincos_reduced(x, c[i], s[i]);
    } else {
      c[i] = std::cos(x);
      s[i] = std::sin(x);
    }
  }
}

}  // namespace gpilqg::gp::ssgp_detail
