/// @file fitted_moment_matcher.cpp
/// The moment matcher of fitted GPs: one table from backend name to the function that reads the
/// fitted models into a matcher (fitted_moment_matcher.hpp says what each reads).

#include "gpilqg/gp/fitted_moment_matcher.hpp"

#include <functional>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/moment_matching.hpp"
#include "gpilqg/gp/ssgp.hpp"
#include "gpilqg/gp/ssgp_moment_matching.hpp"

namespace gpilqg::gp {
namespace {

using Builder = std::function<std::shared_ptr<const MomentMatcher>(const std::vector<const FittedGp*>&)>;

/// The posterior of one output, or a logic error: the backend name said it is of this kind.
template <class Predictor>
const Predictor& posterior(const Predictor* p, std::size_t a) {
  if (p == nullptr)
    throw std::logic_error(fmt::format("moment_matcher_for: outputs[{}] names its backend but is not its fitted type", a));
  return *p;
}

std::shared_ptr<const MomentMatcher> exact_matcher(const std::vector<const FittedGp*>& outputs) {
  std::vector<Matrix> centres;
  std::vector<SeArdOutput> se;
  for (const FittedGp* model : outputs) {
    const TrainingSet& data = model->training_set();
    const Vector& h = model->parameters();
    const int D = model->input_dim();
    se.push_back(condition_se_ard_output(data.inputs, data.targets, h.head(D), h(D), h(D + 1)));
    centres.push_back(data.inputs);
  }
  return std::make_shared<const SeArdMomentMatcher>(std::move(centres), std::move(se));
}

std::shared_ptr<const MomentMatcher> fitc_matcher(const std::vector<const FittedGp*>& outputs) {
  std::vector<Matrix> centres;
  std::vector<SeArdOutput> se;
  for (std::size_t a = 0; a < outputs.size(); ++a) {
    const FitcPredictor& p = posterior(fitc_posterior(*outputs[a]), a);
    const Vector& h = outputs[a]->parameters();
    const int D = p.input_dim();
    // s2 = sf2 + k' C k = sf2 - k' Kinv k with Kinv = -C = Kuu^-1 - (Kuu + Kuf Lambda^-1 Kfu)^-1.
    se.push_back(SeArdOutput{h.head(D), h(D), p.beta(), -p.variance_matrix()});
    centres.push_back(p.inducing_inputs());
  }
  return std::make_shared<const SeArdMomentMatcher>(std::move(centres), std::move(se));
}

std::shared_ptr<const MomentMatcher> ssgp_matcher(const std::vector<const FittedGp*>& outputs) {
  std::vector<SsgpOutput> trig;
  for (std::size_t a = 0; a < outputs.size(); ++a) {
    const SsgpPredictor& p = posterior(ssgp_posterior(*outputs[a]), a);
    trig.push_back(SsgpOutput{p.frequency_matrix(), p.alpha(), p.variance_matrix()});
  }
  return std::make_shared<const SsgpMomentMatcher>(std::move(trig));
}

struct Entry {
  std::string_view backend;
  Builder build;
};

const std::vector<Entry>& builders() {
  static const std::vector<Entry> table = {{"exact", exact_matcher}, {"fitc", fitc_matcher}, {"ssgp", ssgp_matcher}};
  return table;
}

const Entry* find(std::string_view backend) {
  for (const Entry& e : builders())
    if (e.backend == backend) return &e;
  return nullptr;
}

}  // namespace

std::vector<std::string> moment_matching_backends() {
  std::vector<std::string> names;
  for (const std::string& name : backend_names())
    if (find(name) != nullptr) names.push_back(name);
  return names;
}

void require_moment_matching(std::string_view backend, std::string_view who) {
  if (find(backend) != nullptr) return;
  const std::string why =
      backend == "compact"
          ? "the Wendland kernel has no closed-form expectation under a Gaussian input, so the belief cannot be "
            "propagated by exact moment matching"
          : "it has no exact moment matching";
  throw std::invalid_argument(fmt::format("{}{}backend '{}' cannot serve PDDP: {}; the backends that can are {}", who,
                                          who.empty() ? "" : ": ", backend, why,
                                          fmt::join(moment_matching_backends(), ", ")));
}

std::shared_ptr<const MomentMatcher> moment_matcher_for(const std::vector<const FittedGp*>& outputs) {
  if (outputs.empty()) throw std::invalid_argument("moment_matcher_for: outputs is empty, need one fitted GP per output");
  for (std::size_t a = 0; a < outputs.size(); ++a)
    if (outputs[a] == nullptr) throw std::invalid_argument(fmt::format("moment_matcher_for: outputs[{}] is null", a));
  const std::string_view backend = outputs[0]->backend_name();
  require_moment_matching(backend, "moment_matcher_for");
  for (std::size_t a = 1; a < outputs.size(); ++a) {
    if (outputs[a]->backend_name() != backend)
      throw std::invalid_argument(fmt::format("moment_matcher_for: outputs[{}] is a '{}' model, outputs[0] a '{}' one; "
                                              "expected one backend for all outputs",
                                              a, outputs[a]->backend_name(), backend));
    if (outputs[a]->input_dim() != outputs[0]->input_dim())
      throw std::invalid_argument(fmt::format("moment_matcher_for: outputs[{}] has {} inputs, outputs[0] {}", a,
                                              outputs[a]->input_dim(), outputs[0]->input_dim()));
  }
  return find(backend)->build(outputs);
}

}  // namespace gpilqg::gp
