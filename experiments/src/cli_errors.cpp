#include "gpilqg/experiments/cli_errors.hpp"

#include <ostream>
#include <sstream>

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

DescribedError describe_error(const std::exception_ptr& error) {
  std::ostringstream text;
  DescribedError d;
  d.exit_status = run_reporting_errors([&]() -> int { std::rethrow_exception(error); }, text);
  d.message = text.str();
  while (!d.message.empty() && d.message.back() == '\n') d.message.pop_back();
  d.detail = d.message.rfind("error: ", 0) == 0 ? d.message.substr(7) : d.message;
  return d;
}

}  // namespace gpilqg
