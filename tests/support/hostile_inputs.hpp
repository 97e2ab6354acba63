#pragma once
/// @file hostile_inputs.hpp
/// Paths that are not readable regular files of a sane size, for checking that every reader refuses
/// them promptly with its own exception type and a message naming the path (input_file.hpp): a FIFO
/// (opening it blocks until a writer comes), /dev/zero (endless), a directory, a loop of symbolic
/// links, a missing file, and a sparse file one byte over the reader's limit (no disk used).

#include <chrono>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace gpilqg::test {

struct HostileInput {
  std::string name;            ///< e.g. "fifo"
  std::filesystem::path path;  ///< ends in the reader's extension
  std::string problem;         ///< what the message must say after "<path>: "
  bool fifo = false;           ///< a reader stuck on it can be released by opening it for writing
};

/// Makes the hostile inputs in `dir` (created when missing), each named "<name><extension>"; the
/// oversized one is a sparse file of max_bytes + 1 bytes.
std::vector<HostileInput> make_hostile_inputs(const std::filesystem::path& dir, const std::string& extension,
                                              std::uintmax_t max_bytes);

/// Calls `read` on another thread and waits at most `timeout`. Returns the exception it threw (null
/// when it returned normally), or nullopt when it did not return in time; a reader blocked opening
/// the FIFO `release` (when not empty) is then released by opening the FIFO for writing.
std::optional<std::exception_ptr> call_with_timeout(const std::function<void()>& read, std::chrono::seconds timeout,
                                                    const std::filesystem::path& release = {});

/// Checks that `read` refuses every input within 20 s by throwing `Error`, whose message starts with
/// "<path>: <problem>".
template <class Error>
void expect_refuses_hostile_inputs(const std::string& reader, const std::function<void(const std::filesystem::path&)>& read,
                                   const std::vector<HostileInput>& inputs) {
  for (const HostileInput& input : inputs) {
    SCOPED_TRACE(reader + " on the " + input.name + " " + input.path.string());
    const auto outcome = call_with_timeout([&] { read(input.path); }, std::chrono::seconds(20),
                                           input.fifo ? input.path : std::filesystem::path());
    ASSERT_TRUE(outcome.has_value()) << "did not return within 20 s";
    ASSERT_TRUE(*outcome) << "accepted the input";
    try {
      std::rethrow_exception(*outcome);
    } catch (const Error& e) {
      const std::string message = e.what();
      const std::string start = input.path.string() + ": " + input.problem;
      EXPECT_EQ(message.rfind(start, 0), 0u) << message << "\nexpected it to start with\n" << start;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "threw an exception of another type: " << e.what();
    }
  }
}

/// One reader of a table-driven test: its name, the extension and size limit of its files, and a
/// call that reads a file.
struct Reader {
  const char* name;
  const char* extension;
  std::uintmax_t limit;
  std::function<void(const std::filesystem::path&)> read;
};

/// expect_refuses_hostile_inputs for every reader of `readers`, each on its own inputs in a folder
/// of `dir` (removed afterwards).
template <class Error>
void expect_readers_refuse_hostile_inputs(const std::vector<Reader>& readers, const std::filesystem::path& dir) {
  for (std::size_t i = 0; i < readers.size(); ++i) {
    const Reader& r = readers[i];
    const auto inputs = make_hostile_inputs(dir / std::to_string(i), r.extension, r.limit);
    expect_refuses_hostile_inputs<Error>(r.name, r.read, inputs);
  }
  std::filesystem::remove_all(dir);
}

}  // namespace gpilqg::test
