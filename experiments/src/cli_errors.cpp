#include "gpilqg/experiments/cli_errors.hpp"

#include <ostream>

#include "gpilqg/core/measurements.hpp"

namespace gpilqg {

int run_reporting_errors(const std::function<int()>& command, std::ostream& err) {
  try {
    return command();
  } catch (const DataError& e) {
    err << "error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const InputError& e) {
    err << "error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    err << "error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    err << "internal error: " << e.what() << '\n';
    return kExitInternalFailure;
  }
}

}  // namespace gpilqg
