#pragma once
/// @file harnesses.hpp
/// The fuzz harnesses: one function per input format, shared by the libFuzzer programs
/// (fuzz_main.cpp, built with -DGPILQG_BUILD_FUZZERS=ON and clang) and by the GoogleTest that replays
/// the committed corpora and every past finding in the normal test suite (replay_test.cpp).
///
/// Contract checked by every harness, on any bytes:
///  - the reader either returns or throws its documented error type (DataError for measurement
///    files, InputError for TOML configs); any other exception escapes (a finding);
///  - what it returns satisfies the reader's promises (shapes, finite values, strictly increasing
///    times, valid config ranges), else FuzzInvariantViolation (a finding);
///  - accepted measurement data round-trips through both writers bit for bit;
///  - no crash, leak or undefined behaviour (ASan + UBSan in the fuzz and sanitizer builds).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace gpilqg::fuzz {

/// A reader returned something that breaks its documented promises.
class FuzzInvariantViolation : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

using Harness = void (*)(const std::uint8_t* data, std::size_t size);

/// CSV measurement reader (in memory and from a file), for the cart-pole and the quadrotor.
void fuzz_measurements_csv(const std::uint8_t* data, std::size_t size);
/// HDF5 measurement reader on the raw bytes of a file.
void fuzz_measurements_hdf5(const std::uint8_t* data, std::size_t size);
/// HDF5 measurement reader on a structurally valid HDF5 file that the bytes describe: which root
/// attributes exist and with which types, ranks and strings; which objects /episodes holds and under
/// which names; each dataset's type, rank, shape and values (NaN, inf, non-increasing times, ...).
/// Mutations then act on the file's meaning rather than on its byte-level encoding.
void fuzz_measurements_hdf5_structured(const std::uint8_t* data, std::size_t size);
/// Every TOML loader of the command line (kTomlLoaders in harnesses.cpp) on the bytes as a file.
void fuzz_toml_configs(const std::uint8_t* data, std::size_t size);

struct Target {
  std::string_view name;  ///< the folder under tests/fuzz/corpus and tests/fuzz/regressions
  Harness harness;
};
/// All harnesses by name: measurements_csv, measurements_hdf5, measurements_hdf5_structured, toml_configs.
const std::vector<Target>& targets();

/// A private folder for the harnesses' scratch files (created once per process, in /dev/shm when
/// it exists, else the system's temporary folder).
const std::filesystem::path& scratch_dir();

}  // namespace gpilqg::fuzz
