/// The libFuzzer entry point of one harness (harnesses.hpp), chosen at compile time by
/// GPILQG_FUZZ_HARNESS. Anything the harness lets escape is a finding: it is printed and the
/// process aborts, so libFuzzer saves the input as crash-<sha1>.

#include <cstdio>
#include <cstdlib>
#include <exception>

#include "harnesses.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    gpilqg::fuzz::GPILQG_FUZZ_HARNESS(data, size);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\n== finding: uncaught %s\n", e.what());
    std::abort();
  }
  return 0;
}
