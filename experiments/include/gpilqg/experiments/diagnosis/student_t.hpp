#pragma once
/// @file student_t.hpp
/// Small-sample corrections of the diagnosis's statistics, from Student's t distribution (Boost.Math):
/// the quantile of an interval from a delete-one-group jackknife of R replicates, and the held-out
/// share's interval and z score from K batch means (effect_fit.hpp, effect_test.hpp).
///
/// A mean over K groups (a delete-one-group jackknife, batch means) with its standard error estimated
/// from the same K groups has K - 1 degrees of freedom: its studentised value follows Student's t with
/// K - 1 degrees of freedom, not the normal distribution, and with few groups the difference is large
/// (the 97.5% quantile is 4.30 for K = 3, 2.26 for K = 10, 1.96 only as K grows).

namespace gpilqg::diagnosis {

/// The p-quantile of Student's t with `dof` degrees of freedom. Throws std::invalid_argument for dof < 1 or p outside (0, 1).
double student_t_quantile(double p, double dof);

/// The half-width of the 95% interval of a mean with standard error `se` estimated from `batches`
/// groups: t_{0.975, batches - 1} se. Throws std::invalid_argument for batches < 2.
double batch_half_width(double se, int batches);

/// The normal score with the tail probability of t under Student's t with batches - 1 degrees of
/// freedom, Phi^-1(T(t)): a studentised mean of K batches on the normal scale the thresholds use
/// ("z >= 3" needs t >= 9.2 on 4 batches, 3.45 on 20). Infinite values stay infinite; |z| is capped
/// at 37 (the double range of Phi). Throws std::invalid_argument for batches < 2.
double normal_equivalent(double t, int batches);

}  // namespace gpilqg::diagnosis
