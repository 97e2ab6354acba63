#include "stop_signal.hpp"

#include "gpilqg/experiments/cli_errors.hpp"

#include <atomic>
#include <csignal>
#include <cstring>

#include <unistd.h>

namespace gpilqg::cli {
namespace {

/// Written by the handler, read by any thread (rank 0's coordinator too): a lock-free atomic is both
/// async-signal-safe and free of data races, which a volatile sig_atomic_t is not across threads.
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);
struct sigaction g_previous_int, g_previous_term;

void on_stop_signal(int signal) {
  if (g_signal != 0) {  // the second time: stop now
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  g_signal = signal;
  static const char kMessage[] =
      "\nstopping after the current iteration (progress is saved; press Ctrl-C again to stop at once)\n";
  [[maybe_unused]] const auto written = ::write(STDERR_FILENO, kMessage, sizeof(kMessage) - 1);
}

}  // namespace

StopSignalGuard::StopSignalGuard() {
  g_signal = 0;
  struct sigaction action;
  std::memset(&action, 0, sizeof(action));
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &g_previous_int);
  sigaction(SIGTERM, &action, &g_previous_term);
}

StopSignalGuard::~StopSignalGuard() {
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
}

bool StopSignalGuard::stop_requested() { return g_signal != 0; }

int StopSignalGuard::signal_number() { return g_signal.load(); }

int StopSignalGuard::exit_status() {
  const int signal = g_signal.load();
  return kExitSignalBase + (signal != 0 ? signal : SIGTERM);
}

}  // namespace gpilqg::cli
