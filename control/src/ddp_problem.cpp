#include "gpilqg/control/ddp_problem.hpp"

#include <stdexcept>
#include <string>

namespace gpilqg {

void DdpProblem::validate() const {
  if (model == nullptr) throw std::invalid_argument("problem: no model");
  if (cost == nullptr) throw std::invalid_argument("problem: no cost");
  const int n = model->state_dim(), m = model->control_dim();
  if (cost->state_dim() != n || cost->control_dim() != m)
    throw std::invalid_argument("problem: the cost is for " + std::to_string(cost->state_dim()) + " states and " +
                                std::to_string(cost->control_dim()) + " controls; the model has " +
                                std::to_string(n) + " and " + std::to_string(m));
  if (horizon < 1) throw std::invalid_argument("problem: horizon = " + std::to_string(horizon) + "; expected >= 1");
  if (x0.size() != n)
    throw std::invalid_argument("problem: x0 has " + std::to_string(x0.size()) + " entries; expected " +
                                std::to_string(n));
  if (!x0.allFinite()) throw std::invalid_argument("problem: x0 has non-finite entries");
  for (const auto* limit : {&u_min, &u_max})
    if (limit->size() != 0 && limit->size() != m)
      throw std::invalid_argument("problem: control limits have " + std::to_string(limit->size()) +
                                  " entries; expected " + std::to_string(m));
  if (u_min.size() && u_max.size())
    for (int j = 0; j < m; ++j)
      if (!(u_min(j) <= u_max(j)))
        throw std::invalid_argument("problem: u_min[" + std::to_string(j) + "] = " + std::to_string(u_min(j)) +
                                    " exceeds u_max[" + std::to_string(j) + "] = " + std::to_string(u_max(j)));
}

}  // namespace gpilqg
