#include "gpilqg/experiments/plot_script.hpp"

#include <cstdlib>
#include <stdexcept>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

namespace gpilqg {
namespace {

std::string interpreter() {
  const char* env = std::getenv("GPILQG_PYTHON");
  return env != nullptr && *env != '\0' ? env : "/usr/bin/python3";
}

/// Runs argv[0] with the arguments, waits, returns the exit status (-1 when it could not start).
int run_process(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    dup2(STDERR_FILENO, STDOUT_FILENO);  // a script's chatter never mixes into a command's --json output
    execv(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

std::filesystem::path plot_script_dir() {
  if (const char* env = std::getenv("GPILQG_PLOTS_DIR"); env != nullptr && *env != '\0') return env;
#ifdef GPILQG_PLOTS_SOURCE_DIR
  if (std::filesystem::exists(GPILQG_PLOTS_SOURCE_DIR)) return GPILQG_PLOTS_SOURCE_DIR;
#endif
#ifdef GPILQG_PLOTS_INSTALL_DIR
  return GPILQG_PLOTS_INSTALL_DIR;
#else
  return "experiments/plots";
#endif
}

namespace {

void check_plotting(const std::string& python, const std::filesystem::path& path, const std::string& consequence) {
  if (!std::filesystem::exists(path))
    throw std::runtime_error(fmt::format("plotting: no script {} (set GPILQG_PLOTS_DIR to the folder of the plot scripts)",
                                         path.string()));
  if (run_process({python, "-c", "import matplotlib, h5py"}) != 0)
    throw std::runtime_error(fmt::format(
        "plotting: {} cannot import matplotlib and h5py; install python3-matplotlib python3-h5py (Debian) or set "
        "GPILQG_PYTHON{}",
        python, consequence));
}

}  // namespace

void require_plotting(const std::string& script) {
  check_plotting(interpreter(), plot_script_dir() / script, "");
}

void run_plot_script(const std::string& script, const std::filesystem::path& input, const std::filesystem::path& out_dir) {
  const std::string python = interpreter();
  const std::filesystem::path path = plot_script_dir() / script;
  check_plotting(python, path, fmt::format("; the result file {} is complete", input.string()));
  std::filesystem::create_directories(out_dir);
  const int status = run_process({python, path.string(), input.string(), out_dir.string()});
  if (status != 0)
    throw std::runtime_error(fmt::format("plotting: {} {} exited with status {}; the result file {} is complete", python,
                                         path.string(), status, input.string()));
}

}  // namespace gpilqg
