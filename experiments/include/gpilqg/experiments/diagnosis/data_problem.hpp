#pragma once
/// @file data_problem.hpp
/// Who is to blame when a diagnosis stops. The measurements can be unable to support it (too few
/// episodes or samples, a time step that changes, a value past the diverged bound, the states of another
/// system): that is a DataProblem, and the caller names the data's file. Every other
/// std::invalid_argument that leaves diagnose() is the program's own failure (a fit past its own bound,
/// a size that does not match inside the diagnosis) and must never be reported as bad data
/// (blame_for_diagnosis).

#include <stdexcept>
#include <string>
#include <utility>

#include "gpilqg/experiments/cli_errors.hpp"

namespace gpilqg::diagnosis {

/// The measurements cannot support the diagnosis as asked; the message says what they lack and what
/// was expected, without the file's name (the caller adds it).
class DataProblem : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The std::logic_error that reports `failure`, a std::invalid_argument that is not a DataProblem, as
/// the diagnosis's own failure on the data from `source` (run_reporting_errors: "internal error", exit 1).
inline std::logic_error own_failure(const std::string& source, const std::invalid_argument& failure) {
  return std::logic_error(std::string("the diagnosis failed on its own, not because of the data in ") + source + ": " +
                          failure.what());
}

/// Runs `diagnosis` (a call of diagnose() or of a step of it) on the measurements from `source` (a
/// file's path, or how the caller names in-memory data) and returns what it returns. A DataProblem
/// becomes an InputError "<source>: <problem>" (exit 2); any other std::invalid_argument becomes a
/// std::logic_error that says the failure is the diagnosis's own (exit 1, "internal error"), so that a
/// defect of the program is never reported as a defect of the user's file.
template <typename Diagnosis>
auto blame_for_diagnosis(const std::string& source, Diagnosis&& diagnosis) {
  try {
    return std::forward<Diagnosis>(diagnosis)();
  } catch (const DataProblem& e) {
    throw InputError(source + ": " + e.what());
  } catch (const std::invalid_argument& e) {
    throw own_failure(source, e);
  }
}

}  // namespace gpilqg::diagnosis
