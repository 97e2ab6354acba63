#include "gpilqg/experiments/cli_errors.hpp"

#include <ostream>

#include "gpilqg/core/atomic_file.hpp"
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
  } catch (const AtomicWriteError& e) {
    err << "error: " << e.what() << '\n';
    return kExitInternalFailure;
  } catch (const FileWriteError& e) {
    err << "error: " << e.what() << '\n';
    return kExitInternalFailure;
  } catch (const ReportedElsewhere& e) {
    return e.exit_status();
  } catch (const std::exception& e) {
    err << "internal error: " << e.what() << '\n';
    return kExitInternalFailure;
  }
}

}  // namespace gpilqg
