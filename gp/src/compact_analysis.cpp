/// CompactBackend::analyze (compact.hpp): the cost of a factorisation before doing one.

#include "compact_internal.hpp"

namespace gpilqg::gp {

CompactFactorAnalysis CompactBackend::analyze(const TrainingSet& data, const VectorCRef& parameters) const {
  validate_training_set(data, "CompactBackend::analyze");
  detail::check_compact_parameters(parameters, data.input_dim(), "CompactBackend::analyze");
  const detail::WendlandKernel kernel(parameters, data.input_dim());
  const detail::NeighbourGrid grid(data.inputs, kernel.inverse_lengthscales());
  detail::LowerPattern pattern;
  CompactFactorAnalysis analysis;
  if (!grid.lower_pattern(options_.max_factor_nonzeros, options_.threads, pattern)) {
    analysis.over_budget = true;
    return analysis;
  }
  analysis.kernel_nonzeros = pattern.nonzeros();
  detail::CholmodFactorizer factorizer;
  const detail::SymbolicFactor symbolic = factorizer.analyze(pattern);
  analysis.factor_nonzeros = symbolic.nonzeros;
  analysis.factorisation_flops = symbolic.flops;
  analysis.inverse_subset_flops = symbolic.inverse_subset_flops;
  analysis.over_budget = symbolic.nonzeros > static_cast<double>(options_.max_factor_nonzeros);
  return analysis;
}

}  // namespace gpilqg::gp
