#include "hostile_inputs.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <future>
#include <stdexcept>
#include <thread>

namespace gpilqg::test {

std::vector<HostileInput> make_hostile_inputs(const std::filesystem::path& dir, const std::string& extension,
                                              std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  fs::create_directories(dir);
  const auto path = [&](const std::string& name) { return dir / (name + extension); };
  std::vector<HostileInput> inputs;

  if (::mkfifo(path("fifo").c_str(), 0600) != 0) throw std::runtime_error("mkfifo failed for " + path("fifo").string());
  inputs.push_back({"fifo", path("fifo"), "is a FIFO (named pipe), not a regular file", true});

  fs::create_symlink("/dev/zero", path("zero"));
  inputs.push_back({"link to /dev/zero", path("zero"), "is a character device, not a regular file"});

  fs::create_directory(path("folder"));
  inputs.push_back({"directory", path("folder"), "is a folder, not a regular file"});

  fs::create_symlink(path("loop").filename(), path("loop"));  // a link to itself
  inputs.push_back({"symbolic link loop", path("loop"), "too many levels of symbolic links"});

  inputs.push_back({"missing file", path("missing"), "no such file"});

  std::ofstream(path("huge")).close();
  fs::resize_file(path("huge"), max_bytes + 1);  // sparse: no blocks are written
  inputs.push_back({"oversized sparse file", path("huge"),
                    "is " + std::to_string(max_bytes + 1) + " bytes, more than the limit of " + std::to_string(max_bytes)});
  return inputs;
}

std::optional<std::exception_ptr> call_with_timeout(const std::function<void()>& read, std::chrono::seconds timeout,
                                                    const std::filesystem::path& release) {
  std::future<std::exception_ptr> done = std::async(std::launch::async, [&read]() -> std::exception_ptr {
    try {
      read();
      return nullptr;
    } catch (...) {
      return std::current_exception();
    }
  });
  if (done.wait_for(timeout) == std::future_status::ready) return done.get();
  // Still running: release a reader blocked on the FIFO (it then reads an empty file), so that the
  // test fails instead of hanging.
  while (!release.empty() && done.wait_for(std::chrono::milliseconds(100)) != std::future_status::ready) {
    const int fd = ::open(release.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) ::close(fd);
  }
  done.wait();
  return std::nullopt;
}

}  // namespace gpilqg::test
