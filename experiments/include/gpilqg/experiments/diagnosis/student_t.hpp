#pragma once
/// @file student_t.hpp
/// Small-sample corrections of the diagnosis's statistics, from Student's t distribution (Boost.Math):
/// the quantile of an interval from a delete-one-group jackknife of R replicates (effect_fit.hpp).
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

}  // namespace gpilqg::diagnosis
