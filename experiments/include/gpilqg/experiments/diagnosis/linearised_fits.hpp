#pragma once
/// @file linearised_fits.hpp
/// Joint fits of any set of candidate effects at the cost of a small linear solve: what decides
/// whether two effects are aliases, and the screening of the best-subset search (subset_search.hpp).
///
/// Around the base model B (the fit context's model with the effects being refitted at their starts,
/// weighted one-step residual r), effect e moves the weighted prediction along a direction J_e: the
/// secant from B to B with e at its own fitted value, (r(theta_0) - r(theta_e)) / (theta_e - theta_0),
/// for an effect of one parameter whose fit moved it (exact for effects linear in theta, and along
/// the fitted direction for the others: a mass, a delay), else the tangent d phi / d theta at theta_0
/// (central differences). For a set S of candidates, together with the effects P that every fit
/// refits, the least-squares fit on the training rows and what it leaves on the held-out rows are
///
///   theta_S = G_T^-1 b_T,     G = J' J, b = J' r over the columns of S and P,
///   left_H(S) = r_H' r_H - 2 theta_S' b_H + theta_S' G_H theta_S,
///
/// from Gram matrices computed once over all candidates (T training rows, H held-out rows): a subset
/// costs one solve of its own size, so every subset of up to four effects of a library can be scored.
/// The numbers are a linearisation: the search screens with them, then refits its choice exactly
/// (fit_jointly) and scores that on the held-out rows.
///
/// Screening apart from scoring. A search that picks the best of thousands of subsets by their
/// held-out residual and then judges the winner on the same rows selects on noise (the winner's
/// held-out gain is biased upwards, the more so the more subsets were compared). The screening score
/// is therefore a K-fold cross-validation on the training rows alone: the training episodes are dealt
/// into K = min(5, their number) folds in turn, and
///
///   screening_left(S) = sum_f [ r_f' r_f - 2 theta_{-f}' b_f + theta_{-f}' G_f theta_{-f} ],
///   theta_{-f} = (G_T - G_f)^+ (b_T - b_f),
///
/// what the fit on the other folds leaves on fold f, from the folds' Gram matrices (K small solves per
/// subset). The held-out rows then judge only the few subsets refitted exactly.
///
/// With instruments (the inverse-dynamics criterion in its IV form, instrumental_variables.hpp) every
/// fit above is the IV fit the exact refit makes: each column also has its instrument z_e, the same
/// secant or tangent in the instrument context (the regressor at the simulated states, zero on rows
/// without an instrument), and the fits solve Z' J theta = Z' r instead of J' J theta = J' r,
///
///   theta_S = (Z_T' J_T)^+ Z_T' r_T,   theta_{-f} = (Z_T' J_T - Z_f' J_f)^+ (Z_T' r_T - Z_f' r_f),
///
/// while what a fit leaves is still measured on the residual, with G and b as above. Least squares
/// would screen on the bias the instruments remove: a regressor that holds the noise of the
/// residual's own rows (an armature's acceleration, a delay's control) predicts that noise on any
/// fold, so cross-validation alone cannot reject it.

#include <string>
#include <vector>

#include "gpilqg/experiments/diagnosis/effect_fit.hpp"

namespace gpilqg::diagnosis {

/// A joint fit as one effect fit per member (the fit itself, then each refitted effect with its name,
/// parameters, start and estimate): the candidates of a LinearisedFits of that set.
std::vector<EffectFit> member_fits(const EffectFit& fit);

class LinearisedFits {
 public:
  /// Linearises the candidates `fits` (each fitted alone or with `refit`, as rank_effects does) around
  /// context.model with every `refit` effect at its start. Candidates whose fit is not identifiable
  /// keep zero columns (they explain nothing). `threads` candidates at once. `keep_columns`: keep the
  /// columns and the base residual, so that relinearise can replace one candidate's columns (memory:
  /// one double per weighted residual entry and column, on both row sets).
  LinearisedFits(const FitContext& context, const std::vector<EffectFit>& fits, const std::vector<RefitEffect>& refit,
                 int threads = 1, bool keep_columns = false);

  /// Candidate `candidate`'s columns computed again with the effect as `context.model` defines it (a
  /// Coulomb member at another smoothing velocity), every Gram matrix and fold updated; the other
  /// columns and the base residual r are kept, so `context` must give the same r (its model differs
  /// from the one linearised around only in the candidate's own definition). Needs keep_columns.
  /// Costs one candidate's columns instead of every candidate's and r's.
  void relinearise(int candidate, const FitContext& context);

  /// The candidates, in the order of `fits`.
  const std::vector<std::string>& names() const { return names_; }
  int size() const { return static_cast<int>(names_.size()); }
  /// Index of the candidate called `name`, or -1.
  int index(const std::string& name) const;

  /// The weighted held-out squared residual of B (no candidate).
  double heldout_base() const { return base_heldout_; }
  /// The weighted held-out squared residual left by the joint least-squares fit of the candidates
  /// `subset` (indices) with the refitted effects, fitted on the training rows (never below 0).
  double heldout_left(const std::vector<int>& subset) const;

  /// The same on the training rows: what the fit leaves of the weighted training objective.
  double training_left(const std::vector<int>& subset) const;

  /// The cross-validated screening score on the training rows (see the file comment); the training
  /// residual left (training_left) when the training rows hold fewer than two episodes.
  double screening_left(const std::vector<int>& subset) const;
  /// Its terms, one per fold (a single entry, training_left, without folds).
  std::vector<double> screening_folds(const std::vector<int>& subset) const;
  /// The folds of screening_left (0 when it falls back to training_left).
  int folds() const { return static_cast<int>(fold_gram_.size()); }

  /// The share of what `reference` leaves on the held-out rows that `subset` removes:
  /// 1 - left(subset) / left(reference) (0 when the reference leaves nothing).
  double gain(const std::vector<int>& subset, const std::vector<int>& reference) const;

 private:
  /// One candidate or refitted effect: its definition, its value in the base model, its fitted value
  /// (empty for the refitted effects) and whether its fit was usable (else its columns stay 0).
  struct Block {
    LibraryEffect effect;
    Vector theta0;
    Vector fitted;
    bool usable = true;
  };
  std::vector<std::string> names_;
  std::vector<Block> blocks_;  ///< the candidates, then the refitted effects
  bool keep_columns_ = false;
  Matrix JT_, JH_;             ///< with keep_columns: the columns on the training and held-out rows
  Vector r0_train_, r0_heldout_;
  std::vector<Eigen::Index> offset_{0};  ///< candidate e owns columns [offset_[e], offset_[e + 1]); then the refitted
  Eigen::Index refit_columns_ = 0;
  Matrix gram_train_, gram_heldout_;
  Vector cross_train_, cross_heldout_;
  double base_heldout_ = 0.0, base_train_ = 0.0;
  std::vector<Matrix> fold_gram_;  ///< G_f of the training folds
  std::vector<Vector> fold_cross_;
  std::vector<Matrix> rest_gram_;  ///< G_T - G_f: the other folds'
  std::vector<Vector> rest_cross_;
  std::vector<double> fold_base_;
  /// The normal equations the fits solve (file comment): J' J and J' r (gram_train_, cross_train_, the
  /// same objects) for least squares, Z' J and Z' r with instruments; over the training rows and over
  /// the other folds of each fold.
  Matrix fit_gram_train_;
  Vector fit_cross_train_;
  std::vector<Matrix> rest_fit_gram_;
  std::vector<Vector> rest_fit_cross_;
  bool instrumented_ = false;  ///< the criterion has instruments: ZT_ holds them
  Matrix ZT_;                  ///< with instruments: the instrument columns on the training rows
  Vector r0_instruments_;      ///< with instruments and keep_columns: the base residual at the instruments
  /// The first column of block `block`.
  Eigen::Index first_column(std::size_t block) const;
  /// Every Gram matrix, cross product and fold from the columns and the base residual.
  void accumulate(const FitContext& c, const std::vector<int>& train, const Matrix& JT, const Matrix& JH,
                  const Vector& r_train, const Vector& r_heldout);
  /// Block `block`'s columns (on both row sets) and, with instruments, its instrument columns.
  void compute_block(std::size_t block, const ModelSpec& base, const FitContext& c, const std::vector<int>& train,
                     const std::vector<int>& heldout, const Vector& r_train, const Vector& r_heldout,
                     const FitContext* at_instruments, const Vector& r_instruments, Matrix& JT, Matrix& JH);
  /// The columns of `subset` with the refitted effects'.
  std::vector<Eigen::Index> columns_of(const std::vector<int>& subset) const;
  /// What the solution theta of gram_fit theta = cross_fit over `cols` (minimum norm) leaves of
  /// (gram, cross, base): base - 2 theta' cross + theta' gram theta.
  static double left_of(const std::vector<Eigen::Index>& cols, const Matrix& gram_fit, const Vector& cross_fit,
                        const Matrix& gram, const Vector& cross, double base);
  /// What the least-squares fit of `subset` (with the refitted effects) leaves of r'r, with the fit on
  /// the training rows, evaluated with (gram, cross, base).
  double left(const std::vector<int>& subset, const Matrix& gram, const Vector& cross, double base) const;
};

}  // namespace gpilqg::diagnosis
