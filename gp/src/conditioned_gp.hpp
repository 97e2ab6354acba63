#pragma once
/// @file conditioned_gp.hpp
/// Internal: what every fitted model that keeps its training set holds (the data, the parameter vector,
/// the conditioning report), with the FittedGp accessors and the check of a query's size, so that a
/// model implements only conditioning and prediction (the compact model; the exact one can move onto it
/// once main's exact_prediction refactoring is merged).

#include <stdexcept>
#include <string>
#include <utility>

#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp::detail {

class ConditionedGp : public FittedGp {
 public:
  ConditionedGp(TrainingSet data, const VectorCRef& parameters) : data_(std::move(data)), parameters_(parameters) {}

  int input_dim() const override { return data_.input_dim(); }
  const TrainingSet& training_set() const override { return data_; }
  const Vector& parameters() const override { return parameters_; }
  const ConditioningReport& conditioning() const override { return report_; }

 protected:
  /// Throws std::invalid_argument "<who>::predict: input has n entries; expected D".
  void check_query(const VectorCRef& z, const char* who) const {
    if (z.size() != input_dim())
      throw std::invalid_argument(std::string(who) + "::predict: input has " + std::to_string(z.size()) +
                                  " entries; expected " + std::to_string(input_dim()));
  }

  TrainingSet data_;
  Vector parameters_;
  ConditioningReport report_;
};

}  // namespace gpilqg::gp::detail
