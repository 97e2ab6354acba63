#pragma once
/// @file subset_exchange.hpp
/// The moves of the greedy part of the subset search (subset_search.hpp) on cross-validated screening
/// scores: the one-standard-error rule that a move must pass, and the exchange of members.
///
/// Forward growth keeps every member it took. A member taken early as the best proxy of several
/// effects not yet in the set (a constant body force standing for a link's mass error and a torque
/// sensor's offset at once) stays after those effects come in, and the data then keep it significant
/// for what little it still fits. Sequential replacement (Miller, "Subset Selection in Regression",
/// 2nd ed., 2002, section 3.5; the `seqrep` method of R's leaps) repairs this at a fixed size: while
/// exchanging one member for one candidate outside the set lowers the score, the exchange of the least
/// score is made. Here an exchange must pass the same rule as a growth, so the folds have to agree on it.

#include <functional>
#include <utility>
#include <vector>

namespace gpilqg::diagnosis {

/// The cross-validated screening score of a set of candidates (indices), fold by fold: what its fit on
/// the other folds leaves on each fold (LinearisedFits::screening_folds).
using FoldScores = std::function<std::vector<double>(const std::vector<int>&)>;

/// Whether candidates a and b may be in one set (a == b: whether a may be in any set).
using MayJoin = std::function<bool(int, int)>;

/// Whether the set scoring `after` fold by fold screens better than the one scoring `before` by more
/// than the noise of the cross-validation: the reduction summed over the K folds, D = sum_f d_f with
/// d_f = before_f - after_f, must exceed its standard error sqrt(K / (K - 1) sum_f (d_f - D / K)^2) (the
/// one-standard-error rule of cross-validated model selection: Breiman, Friedman, Olshen and Stone;
/// Hastie, Tibshirani and Friedman, 7.10). With one fold, any reduction. Throws std::invalid_argument
/// when the two have different numbers of folds. A reduction below
/// sqrt(machine epsilon) = 1.5e-8 of the score is rounding, not a reduction: two candidates with the same
/// column (MuJoCo's joint damping and the library's viscous friction under inverse dynamics) differ in
/// score by 1e-14 of it, with folds that agree exactly.
bool lowers_by_more_than_its_error(const std::vector<double>& before, const std::vector<double>& after);

/// One exchange made: the member `out` replaced by the candidate `in`.
struct Exchange {
  int out = -1;
  int in = -1;
};

/// `set` improved by sequential replacement among the candidates 0 .. candidates - 1: each round scores
/// every set that differs from it in one member (each member in turn for each candidate outside the set
/// that may join the others) and makes, of the exchanges that lower the score by more than its standard
/// error (lowers_by_more_than_its_error), the one of the least score, as a growth takes the least
/// growth that passes (the least score alone may be a reduction the folds disagree on); rounds go on
/// until none passes. The score falls strictly at each exchange, so no set comes back; at most
/// `max_rounds` rounds. `made`, when given, receives the exchanges in order. The members keep their
/// positions (the first stays first unless it is exchanged).
std::vector<int> exchanged(const FoldScores& folds, int candidates, std::vector<int> set, const MayJoin& may_join,
                           int max_rounds, std::vector<Exchange>* made = nullptr);

}  // namespace gpilqg::diagnosis
