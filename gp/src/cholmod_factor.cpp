#include "cholmod_factor.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace gpilqg::gp::detail {

struct CholmodFactorizer::Impl {
  cholmod_common common{};

  Impl() {
    cholmod_start(&common);
    common.print = 0;                          // "not positive definite" is a status here, not a message
    common.supernodal = CHOLMOD_SUPERNODAL;    // always LL' (dpotrf per supernode), see factorize()
    common.quick_return_if_not_posdef = 1;  // stop at the first failing supernode
    common.final_asis = 1;                  // converted explicitly after the pivot check
  }
  ~Impl() { cholmod_finish(&common); }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  /// Frees a factor with this common.
  struct FactorDeleter {
    cholmod_common* common;
    void operator()(cholmod_factor* factor) const { cholmod_free_factor(&factor, common); }
  };
  using FactorPtr = std::unique_ptr<cholmod_factor, FactorDeleter>;

  [[noreturn]] void fail(const char* what) const {
    throw std::runtime_error(std::string("CHOLMOD ") + what + " failed with status " + std::to_string(common.status) +
                             (common.status == CHOLMOD_OUT_OF_MEMORY ? " (out of memory)" : ""));
  }
};

namespace {

/// A cholmod_sparse header over the caller's arrays (no copy; CHOLMOD only reads them); without
/// `values`, the pattern alone.
cholmod_sparse lower_view(const LowerPattern& pattern, const std::vector<double>* values) {
  cholmod_sparse a{};
  a.nrow = static_cast<std::size_t>(pattern.size);
  a.ncol = static_cast<std::size_t>(pattern.size);
  a.nzmax = pattern.row.size();
  a.p = const_cast<int*>(pattern.column_start.data());
  a.i = const_cast<int*>(pattern.row.data());
  a.x = values != nullptr ? const_cast<double*>(values->data()) : nullptr;
  a.stype = -1;  // lower triangle stored
  a.itype = CHOLMOD_INT;
  a.xtype = values != nullptr ? CHOLMOD_REAL : CHOLMOD_PATTERN;
  a.dtype = CHOLMOD_DOUBLE;
  a.sorted = 1;
  a.packed = 1;
  return a;
}

/// Copies a supernodal numerical factor (int indices) into plain arrays.
void copy_supernodal(const cholmod_factor& l, SupernodalFactor& out) {
  const auto n = static_cast<int>(l.n);
  const auto supernodes = static_cast<std::size_t>(l.nsuper);
  const auto* super = static_cast<const int*>(l.super);
  const auto* pi = static_cast<const int*>(l.pi);
  const auto* px = static_cast<const int*>(l.px);
  const auto* ls = static_cast<const int*>(l.s);
  const auto* x = static_cast<const double*>(l.x);
  const auto* perm = static_cast<const int*>(l.Perm);
  out.size = n;
  out.first_column.assign(super, super + supernodes + 1);
  out.row_start.assign(pi, pi + supernodes + 1);
  out.value_start.assign(px, px + supernodes + 1);
  out.rows.assign(ls, ls + pi[supernodes]);
  out.value.assign(x, x + px[supernodes]);
  out.permutation.assign(perm, perm + n);
  out.inverse_permutation.resize(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) out.inverse_permutation[static_cast<std::size_t>(perm[k])] = k;
  for (std::size_t s = 0; s < supernodes; ++s)
    for (int c = 0; c < super[s + 1] - super[s]; ++c)
      if (ls[pi[s] + c] != super[s] + c)
        throw std::logic_error("CHOLMOD supernode " + std::to_string(s) + " does not list its own columns first");
}

}  // namespace

CholmodFactorizer::CholmodFactorizer() : impl_(std::make_unique<Impl>()) {}
CholmodFactorizer::~CholmodFactorizer() = default;

SymbolicFactor CholmodFactorizer::analyze(const LowerPattern& pattern) {
  cholmod_common* c = &impl_->common;
  cholmod_sparse a = lower_view(pattern, nullptr);
  Impl::FactorPtr l(cholmod_analyze(&a, c), Impl::FactorDeleter{c});
  if (!l) impl_->fail("analysis");
  SymbolicFactor symbolic{c->lnz, c->fl, 0.0};
  if (l->is_super) {
    const auto* super = static_cast<const int*>(l->super);
    const auto* pi = static_cast<const int*>(l->pi);
    for (std::size_t s = 0; s < l->nsuper; ++s) {
      const double columns = super[s + 1] - super[s], below = pi[s + 1] - pi[s] - columns;
      symbolic.inverse_subset_flops +=
          3.0 * columns * columns * columns + 4.0 * below * columns * columns + 2.0 * below * below * columns;
    }
  }
  return symbolic;
}

SparseFactorOutcome CholmodFactorizer::factorize(const LowerPattern& pattern, const std::vector<double>& values,
                                                 double noise_variance, double scale, const JitterSchedule& schedule,
                                                 std::int64_t max_factor_nonzeros, SupernodalFactor& factor) {
  cholmod_common* c = &impl_->common;
  cholmod_sparse a = lower_view(pattern, &values);
  Impl::FactorPtr l(cholmod_analyze(&a, c), Impl::FactorDeleter{c});
  if (!l) impl_->fail("analysis");
  SparseFactorOutcome outcome;
  outcome.factor_nonzeros = std::max(c->lnz, static_cast<double>(l->xsize));
  if (outcome.factor_nonzeros > static_cast<double>(max_factor_nonzeros)) {
    outcome.over_budget = true;
    return outcome;
  }
  double largest_diagonal = 0.0;
  for (int j = 0; j < pattern.size; ++j)
    largest_diagonal = std::max(largest_diagonal, values[static_cast<std::size_t>(pattern.column_start[static_cast<std::size_t>(j)])]);
  const double floor_scale = std::max(scale, 1e-300);
  auto attempt = [&](double jitter) {
    double beta[2] = {noise_variance + jitter, 0.0};
    cholmod_factorize_p(&a, beta, nullptr, 0, l.get(), c);
    if (c->status < CHOLMOD_OK) impl_->fail("numerical factorisation");
    if (c->status == CHOLMOD_NOT_POSDEF || l->minor < l->n || !l->is_super) return false;
    copy_supernodal(*l, factor);
    return factor.smallest_pivot() > 16.0 * std::numeric_limits<double>::epsilon() * (largest_diagonal + beta[0]);
  };
  bool ok = attempt(0.0);
  if (ok) {
    outcome.status = FactorStatus::Ok;
  } else {
    for (double relative = schedule.first; relative <= schedule.last * (1.0 + 1e-12); relative *= schedule.growth) {
      outcome.jitter = relative * floor_scale;
      if ((ok = attempt(outcome.jitter))) break;
    }
    if (!ok) {
      outcome.status = FactorStatus::Failed;
      outcome.jitter = schedule.last * floor_scale;
      return outcome;
    }
    outcome.status = FactorStatus::JitterAdded;
  }
  return outcome;
}

}  // namespace gpilqg::gp::detail
