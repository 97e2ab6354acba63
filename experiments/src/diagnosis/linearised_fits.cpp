#include "gpilqg/experiments/diagnosis/linearised_fits.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <Eigen/Dense>

#include "gpilqg/core/fork_join.hpp"
#include "gpilqg/experiments/diagnosis/affine_force_residual.hpp"
#include "gpilqg/experiments/diagnosis/criteria/inverse_dynamics.hpp"
#include "gpilqg/experiments/diagnosis/instrumental_variables.hpp"

namespace gpilqg::diagnosis {

namespace {

/// The weighted residual on the training rows and on the held-out rows.
struct Split {
  Vector train, heldout;
};

Split residual_split(const ModelSpec& model, const FitContext& c, const std::vector<int>& train,
                     const std::vector<int>& heldout) {
  return {weighted_residual_of(model, c, train), weighted_residual_of(model, c, heldout)};
}

/// The columns of one effect: d phi / d theta on both row sets (a secant or central differences; see
/// the file comment). The residual is x' - phi, so d phi / d theta = -(d residual / d theta).
std::pair<Matrix, Matrix> columns(const ModelSpec& base, const Split& r0, const LibraryEffect& effect, const Vector& theta0,
                                  const Vector* fitted, const FitContext& c, const std::vector<int>& train,
                                  const std::vector<int>& heldout) {
  // Inverse dynamics with a force linear in its parameters: secant and tangent are both the force's
  // own regressor (affine_force_residual.hpp), without evaluating the model.
  if (c.criterion->inverse_dynamics() && linear_forces({&effect}))
    return {weighted_force_regressor(base, {&effect}, c, train), weighted_force_regressor(base, {&effect}, c, heldout)};
  const auto p = static_cast<Eigen::Index>(effect.parameters.size());
  Matrix JT(r0.train.size(), p), JH(r0.heldout.size(), p);
  if (p == 1 && fitted != nullptr && fitted->size() == 1 && (*fitted)(0) != theta0(0)) {
    const Split r = residual_split(base.with(effect, *fitted), c, train, heldout);
    const double step = (*fitted)(0) - theta0(0);
    JT.col(0) = (r0.train - r.train) / step;
    JH.col(0) = (r0.heldout - r.heldout) / step;
    return {JT, JH};
  }
  for (Eigen::Index j = 0; j < p; ++j) {
    const DifferenceStep d = difference_step(effect.parameters[static_cast<std::size_t>(j)], theta0, j);
    const Split a = residual_split(base.with(effect, d.minus), c, train, heldout);
    const Split b = residual_split(base.with(effect, d.plus), c, train, heldout);
    JT.col(j) = (a.train - b.train) * d.inverse_width();
    JH.col(j) = (a.heldout - b.heldout) * d.inverse_width();
  }
  return {JT, JH};
}

}  // namespace

LinearisedFits::LinearisedFits(const FitContext& c, const std::vector<EffectFit>& fits,
                               const std::vector<RefitEffect>& refit, int threads, bool keep_columns)
    : keep_columns_(keep_columns) {
  const std::vector<int> train = c.data->rows(false), heldout = c.data->rows(true);
  ModelSpec base = c.model;
  for (const RefitEffect& r : refit) base = base.with(*r.effect, r.start);
  const Split r0 = residual_split(base, c, train, heldout);
  const InverseDynamicsCriterion* criterion = c.criterion->inverse_dynamics();
  instrumented_ = criterion != nullptr && criterion->instruments() != nullptr;
  const std::optional<FitContext> at_instruments =
      instrumented_ ? std::optional<FitContext>(instrument_context(c)) : std::nullopt;
  const Vector r_instruments = instrumented_ ? weighted_residual_of(base, *at_instruments, train) : Vector();

  // Candidates first, then the refitted effects; each block of columns computed on its own.
  for (const EffectFit& f : fits) {
    names_.push_back(f.effect);
    LibraryEffect effect = find_candidate(c.model, f.effect);
    const Vector theta0 = base.current_values(effect);
    blocks_.push_back({std::move(effect), theta0, f.estimate, f.identifiable});
    offset_.push_back(offset_.back() + static_cast<Eigen::Index>(f.parameters.size()));
  }
  for (const RefitEffect& r : refit) {
    blocks_.push_back({*r.effect, r.start, Vector(), true});
    refit_columns_ += static_cast<Eigen::Index>(r.effect->parameters.size());
  }
  const Eigen::Index P = offset_.back() + refit_columns_;
  Matrix JT = Matrix::Zero(r0.train.size(), P), JH = Matrix::Zero(r0.heldout.size(), P);
  if (instrumented_) ZT_ = Matrix::Zero(r0.train.size(), P);
  std::atomic<std::size_t> next{0};
  ForkJoin workers;
  workers.run(std::max(1, std::min<int>(threads, static_cast<int>(blocks_.size()))), [&](int, int) {
    for (std::size_t b = next++; b < blocks_.size(); b = next++)
      compute_block(b, base, c, train, heldout, r0.train, r0.heldout, at_instruments ? &*at_instruments : nullptr,
                    r_instruments, JT, JH);
  });
  accumulate(c, train, JT, JH, r0.train, r0.heldout);
  if (keep_columns_) {
    JT_ = std::move(JT);
    JH_ = std::move(JH);
    r0_train_ = r0.train;
    r0_heldout_ = r0.heldout;
    r0_instruments_ = r_instruments;
  }
}

void LinearisedFits::compute_block(std::size_t b, const ModelSpec& base, const FitContext& c,
                                   const std::vector<int>& train, const std::vector<int>& heldout, const Vector& r_train,
                                   const Vector& r_heldout, const FitContext* at_instruments,
                                   const Vector& r_instruments, Matrix& JT, Matrix& JH) {
  const Block& block = blocks_[b];
  const Eigen::Index first = first_column(b), p = static_cast<Eigen::Index>(block.effect.parameters.size());
  const auto clear = [&] {
    JT.middleCols(first, p).setZero();
    JH.middleCols(first, p).setZero();
    if (instrumented_) ZT_.middleCols(first, p).setZero();
  };
  clear();
  if (!block.usable) return;
  auto [T, H] = columns(base, {r_train, r_heldout}, block.effect, block.theta0, &block.fitted, c, train, heldout);
  if (!T.allFinite() || !H.allFinite()) return;
  if (at_instruments != nullptr) {
    // The same column at the simulated states, on the training rows only (the fits use no other).
    Matrix Z = columns(base, {r_instruments, Vector()}, block.effect, block.theta0, &block.fitted, *at_instruments,
                       train, {})
                   .first;
    zero_uninstrumented(Z, *c.criterion->inverse_dynamics()->instruments(), train);
    if (!Z.allFinite()) return;
    ZT_.middleCols(first, p) = Z;
  }
  JT.middleCols(first, p) = T;
  JH.middleCols(first, p) = H;
}

Eigen::Index LinearisedFits::first_column(std::size_t block) const {
  Eigen::Index col = 0;
  for (std::size_t b = 0; b < block; ++b) col += static_cast<Eigen::Index>(blocks_[b].effect.parameters.size());
  return col;
}

void LinearisedFits::accumulate(const FitContext& c, const std::vector<int>& train, const Matrix& JT, const Matrix& JH,
                                const Vector& r_train, const Vector& r_heldout) {
  const Eigen::Index P = JT.cols();
  gram_train_ = JT.transpose() * JT;
  gram_heldout_ = JH.transpose() * JH;
  cross_train_ = JT.transpose() * r_train;
  cross_heldout_ = JH.transpose() * r_heldout;
  base_heldout_ = r_heldout.squaredNorm();
  base_train_ = r_train.squaredNorm();
  fit_gram_train_ = instrumented_ ? Matrix(ZT_.transpose() * JT) : gram_train_;
  fit_cross_train_ = instrumented_ ? Vector(ZT_.transpose() * r_train) : cross_train_;

  // The screening folds: the training episodes dealt in turn into K = min(5, episodes) folds.
  fold_gram_.clear();
  fold_cross_.clear();
  fold_base_.clear();
  rest_gram_.clear();
  rest_cross_.clear();
  rest_fit_gram_.clear();
  rest_fit_cross_.clear();
  std::vector<int> episodes;
  for (int r : train) {
    const int e = c.data->episode[static_cast<std::size_t>(r)];
    if (std::find(episodes.begin(), episodes.end(), e) == episodes.end()) episodes.push_back(e);
  }
  const int K = std::min<int>(5, static_cast<int>(episodes.size()));
  if (K < 2) return;
  const auto n = static_cast<Eigen::Index>(c.weights.size());
  fold_gram_.assign(static_cast<std::size_t>(K), Matrix::Zero(P, P));
  fold_cross_.assign(static_cast<std::size_t>(K), Vector::Zero(P));
  fold_base_.assign(static_cast<std::size_t>(K), 0.0);
  std::vector<Matrix> fold_fit_gram(instrumented_ ? static_cast<std::size_t>(K) : 0, Matrix::Zero(P, P));
  std::vector<Vector> fold_fit_cross(instrumented_ ? static_cast<std::size_t>(K) : 0, Vector::Zero(P));
  for (std::size_t k = 0; k < train.size(); ++k) {
    const int e = c.data->episode[static_cast<std::size_t>(train[k])];
    const auto f = static_cast<std::size_t>((std::find(episodes.begin(), episodes.end(), e) - episodes.begin()) % K);
    const auto rows = JT.middleRows(static_cast<Eigen::Index>(k) * n, n);
    const auto r = r_train.segment(static_cast<Eigen::Index>(k) * n, n);
    fold_gram_[f].noalias() += rows.transpose() * rows;
    fold_cross_[f].noalias() += rows.transpose() * r;
    fold_base_[f] += r.squaredNorm();
    if (instrumented_) {
      const auto z = ZT_.middleRows(static_cast<Eigen::Index>(k) * n, n);
      fold_fit_gram[f].noalias() += z.transpose() * rows;
      fold_fit_cross[f].noalias() += z.transpose() * r;
    }
  }
  for (std::size_t f = 0; f < fold_gram_.size(); ++f) {
    rest_gram_.push_back(gram_train_ - fold_gram_[f]);
    rest_cross_.push_back(cross_train_ - fold_cross_[f]);
    rest_fit_gram_.push_back(instrumented_ ? Matrix(fit_gram_train_ - fold_fit_gram[f]) : rest_gram_.back());
    rest_fit_cross_.push_back(instrumented_ ? Vector(fit_cross_train_ - fold_fit_cross[f]) : rest_cross_.back());
  }
}

void LinearisedFits::relinearise(int candidate, const FitContext& c) {
  if (!keep_columns_) throw std::logic_error("LinearisedFits::relinearise: the columns were not kept");
  if (candidate < 0 || candidate >= size()) throw std::out_of_range("LinearisedFits::relinearise: no such candidate");
  const auto b = static_cast<std::size_t>(candidate);
  Block& block = blocks_[b];
  if (!block.usable) return;
  const std::vector<int> train = c.data->rows(false), heldout = c.data->rows(true);
  ModelSpec base = c.model;
  for (std::size_t r = static_cast<std::size_t>(size()); r < blocks_.size(); ++r)
    base = base.with(blocks_[r].effect, blocks_[r].theta0);
  block.effect = find_candidate(c.model, names_[b]);
  const std::optional<FitContext> at_instruments =
      instrumented_ ? std::optional<FitContext>(instrument_context(c)) : std::nullopt;
  compute_block(b, base, c, train, heldout, r0_train_, r0_heldout_, at_instruments ? &*at_instruments : nullptr,
                r0_instruments_, JT_, JH_);
  accumulate(c, train, JT_, JH_, r0_train_, r0_heldout_);
}

std::vector<EffectFit> member_fits(const EffectFit& fit) {
  std::vector<EffectFit> members{fit};
  for (const EffectValues& v : fit.refitted) {
    EffectFit member;
    member.effect = v.effect;
    member.parameters = v.parameters;
    member.initial = v.initial;
    member.estimate = v.estimate;
    members.push_back(std::move(member));
  }
  return members;
}

int LinearisedFits::index(const std::string& name) const {
  const auto it = std::find(names_.begin(), names_.end(), name);
  return it == names_.end() ? -1 : static_cast<int>(it - names_.begin());
}

double LinearisedFits::heldout_left(const std::vector<int>& subset) const {
  return left(subset, gram_heldout_, cross_heldout_, base_heldout_);
}

double LinearisedFits::training_left(const std::vector<int>& subset) const {
  return left(subset, gram_train_, cross_train_, base_train_);
}

std::vector<Eigen::Index> LinearisedFits::columns_of(const std::vector<int>& subset) const {
  std::vector<Eigen::Index> cols;
  for (int e : subset)
    for (Eigen::Index j = offset_[static_cast<std::size_t>(e)]; j < offset_[static_cast<std::size_t>(e) + 1]; ++j)
      cols.push_back(j);
  for (Eigen::Index j = 0; j < refit_columns_; ++j) cols.push_back(offset_.back() + j);
  return cols;
}

double LinearisedFits::left_of(const std::vector<Eigen::Index>& cols, const Matrix& gram_fit, const Vector& cross_fit,
                               const Matrix& gram, const Vector& cross, double base) {
  if (cols.empty()) return base;
  const auto k = static_cast<Eigen::Index>(cols.size());
  Matrix GT(k, k), G(k, k);
  Vector bT(k), b(k);
  for (Eigen::Index a = 0; a < k; ++a) {
    bT(a) = cross_fit(cols[static_cast<std::size_t>(a)]);
    b(a) = cross(cols[static_cast<std::size_t>(a)]);
    for (Eigen::Index c = 0; c < k; ++c) {
      GT(a, c) = gram_fit(cols[static_cast<std::size_t>(a)], cols[static_cast<std::size_t>(c)]);
      G(a, c) = gram(cols[static_cast<std::size_t>(a)], cols[static_cast<std::size_t>(c)]);
    }
  }
  // The minimum-norm solution: collinear columns (aliases) share the fit instead of blowing up.
  const Vector theta = GT.completeOrthogonalDecomposition().solve(bT);
  if (!theta.allFinite()) return base;
  return std::max(0.0, base - 2.0 * theta.dot(b) + theta.dot(G * theta));
}

double LinearisedFits::left(const std::vector<int>& subset, const Matrix& gram, const Vector& cross, double base) const {
  return left_of(columns_of(subset), fit_gram_train_, fit_cross_train_, gram, cross, base);
}

double LinearisedFits::screening_left(const std::vector<int>& subset) const {
  double total = 0.0;
  for (double term : screening_folds(subset)) total += term;
  return total;
}

std::vector<double> LinearisedFits::screening_folds(const std::vector<int>& subset) const {
  if (fold_gram_.empty()) return {training_left(subset)};
  const std::vector<Eigen::Index> cols = columns_of(subset);
  std::vector<double> out;
  for (std::size_t f = 0; f < fold_gram_.size(); ++f)
    out.push_back(left_of(cols, rest_fit_gram_[f], rest_fit_cross_[f], fold_gram_[f], fold_cross_[f], fold_base_[f]));
  return out;
}

double LinearisedFits::gain(const std::vector<int>& subset, const std::vector<int>& reference) const {
  const double before = heldout_left(reference);
  return before > 0.0 ? 1.0 - heldout_left(subset) / before : 0.0;
}

}  // namespace gpilqg::diagnosis
