/// write_atomically / update_atomically (atomic_file.hpp): a writer that fails half-way leaves the
/// previous file byte for byte and no temporary file behind; the measurement writers go through it.

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <fstream>
#include <iterator>
#include <stdexcept>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

std::string contents(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void put(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << text;
}

/// The names in `folder`, sorted.
std::vector<std::string> listing(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(AtomicFile, WritesANewFileAndReplacesAnOldOne) {
  const auto dir = test::temporary_dir("atomic_new");
  const auto target = dir / "result.txt";
  std::filesystem::path seen;
  write_atomically(target, [&](const std::filesystem::path& temporary) {
    seen = temporary;
    EXPECT_FALSE(std::filesystem::exists(temporary));
    EXPECT_EQ(temporary.parent_path(), dir);  // same folder: the rename is atomic
    EXPECT_TRUE(is_atomic_temporary(temporary)) << temporary;
    put(temporary, "first");
  });
  EXPECT_EQ(contents(target), "first");
  write_atomically(target, [](const std::filesystem::path& temporary) { put(temporary, "second"); });
  EXPECT_EQ(contents(target), "second");
  EXPECT_EQ(listing(dir), std::vector<std::string>{"result.txt"});
  EXPECT_NE(atomic_temporary_path(target), atomic_temporary_path(target));  // fresh names
}

TEST(AtomicFile, AWriterThatThrowsMidwayLeavesThePreviousFileByteIdentical) {
  const auto dir = test::temporary_dir("atomic_throw");
  const auto target = dir / "result.h5";
  const std::string previous("previous\0contents\n", 18);
  put(target, previous);
  auto half_then_throw = [](const std::filesystem::path& temporary) {
    put(temporary, "half a fi");
    throw std::runtime_error("disk on fire");
  };
  EXPECT_THROW(
      {
        try {
          write_atomically(target, half_then_throw);
        } catch (const std::runtime_error& e) {
          EXPECT_STREQ(e.what(), "disk on fire");  // the writer's exception, unchanged
          throw;
        }
      },
      std::runtime_error);
  EXPECT_EQ(contents(target), previous);
  EXPECT_EQ(listing(dir), std::vector<std::string>{"result.h5"});  // no temporary left behind
  // The same with update_atomically (the temporary starts as a copy).
  EXPECT_THROW(update_atomically(target, half_then_throw), std::runtime_error);
  EXPECT_EQ(contents(target), previous);
  EXPECT_EQ(listing(dir), std::vector<std::string>{"result.h5"});
  // No file before: still none after.
  EXPECT_THROW(write_atomically(dir / "new.h5", half_then_throw), std::runtime_error);
  EXPECT_EQ(listing(dir), std::vector<std::string>{"result.h5"});
}

TEST(AtomicFile, UpdateStartsFromACopyOfThePreviousFile) {
  const auto dir = test::temporary_dir("atomic_update");
  const auto target = dir / "log.txt";
  update_atomically(target, [](const std::filesystem::path& temporary) {
    EXPECT_FALSE(std::filesystem::exists(temporary));
    put(temporary, "a");
  });
  update_atomically(target, [](const std::filesystem::path& temporary) {
    EXPECT_EQ(contents(temporary), "a");
    std::ofstream(temporary, std::ios::app) << "b";
  });
  EXPECT_EQ(contents(target), "ab");
}

TEST(AtomicFile, MachineryFailuresAreErrorsNamingTheTarget) {
  const auto dir = test::temporary_dir("atomic_errors");
  // The writer forgot to write.
  try {
    write_atomically(dir / "out.csv", [](const std::filesystem::path&) {});
    ADD_FAILURE() << "no error";
  } catch (const AtomicWriteError& e) {
    EXPECT_EQ(e.target(), dir / "out.csv");
    EXPECT_NE(std::string(e.what()).find("did not create the temporary file"), std::string::npos) << e.what();
  }
  // The target is a folder: the rename fails, the folder stays, the temporary goes.
  std::filesystem::create_directory(dir / "folder");
  EXPECT_THROW(write_atomically(dir / "folder", [](const std::filesystem::path& t) { put(t, "x"); }),
               AtomicWriteError);
  EXPECT_TRUE(std::filesystem::is_directory(dir / "folder"));
  EXPECT_EQ(listing(dir), std::vector<std::string>{"folder"});
  EXPECT_FALSE(is_atomic_temporary("result.h5"));
  EXPECT_FALSE(is_atomic_temporary("result.tmp-12"));
  EXPECT_TRUE(is_atomic_temporary("result.h5.tmp-12-0"));
}

TEST(AtomicFile, MeasurementWritersLeaveThePreviousFileOnFailure) {
  const auto dir = test::temporary_dir("atomic_measurements");
  MeasurementSet set;
  set.system = system_signature("cartpole");
  Episode e;
  e.t = Vector::LinSpaced(3, 0.0, 0.1);
  e.x = Matrix::Ones(3, 4);
  e.u = Matrix::Zero(3, 1);
  set.episodes.push_back(e);
  for (const char* name : {"data.csv", "data.h5"}) {
    const auto file = dir / name;
    write_measurements(file, set);
    const std::string before = contents(file);
    MeasurementSet bad = set;
    bad.episodes[0].x(1, 2) = std::nan("");
    EXPECT_THROW(write_measurements(file, bad), std::invalid_argument);
    EXPECT_EQ(contents(file), before) << name;
  }
  // A folder in the way fails the rename: an AtomicWriteError naming the file (the CLI refuses such
  // an --out before any work, output_path.hpp).
  std::filesystem::create_directory(dir / "taken.csv");
  EXPECT_THROW(write_measurements(dir / "taken.csv", set), AtomicWriteError);
  EXPECT_EQ(listing(dir), (std::vector<std::string>{"data.csv", "data.h5", "taken.csv"}));
}

TEST(AtomicFile, TemporaryNamesFitTheFileNameLimitAndStayRecognisable) {
  const auto dir = test::temporary_dir("atomic_names");
  for (const std::size_t length : {1u, 200u, 250u, 255u}) {
    const std::filesystem::path target = dir / std::string(length, 'n');
    const std::filesystem::path temporary = atomic_temporary_path(target);
    EXPECT_LE(temporary.filename().string().size(), 255u) << length;
    EXPECT_EQ(temporary.parent_path(), dir);
    EXPECT_TRUE(is_atomic_temporary(temporary)) << temporary;
    write_file_atomically(target, "contents");
    EXPECT_EQ(contents(target), "contents") << length;
  }
  // Two long names that differ only at their end get different temporary names.
  const std::string a = atomic_temporary_path(dir / (std::string(250, 'n') + "a")).filename().string();
  const std::string b = atomic_temporary_path(dir / (std::string(250, 'n') + "b")).filename().string();
  EXPECT_NE(a.substr(0, a.rfind(".tmp-")), b.substr(0, b.rfind(".tmp-")));
}

TEST(AtomicFile, StaleTemporariesAreThoseOfProcessesThatEnded) {
  const auto dir = test::temporary_dir("atomic_stale");
  const std::filesystem::path target = dir / "result.h5";
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  auto named = [&](long pid) {
    std::string name = atomic_temporary_path(target).filename().string();
    return dir / (name.substr(0, name.rfind(".tmp-") + 5) + std::to_string(pid) + "-3");
  };
  for (const auto& file : {named(child), named(::getpid()), named(1), dir / "other.h5.tmp-1-1"}) std::ofstream(file) << "x";
  EXPECT_EQ(stale_temporaries(target), std::vector<std::filesystem::path>{named(child)});
  EXPECT_EQ(stale_temporaries_in(dir), std::vector<std::filesystem::path>{named(child)});
}

TEST(AtomicFile, AFileSizeLimitFailsTheWriteWithTheOsErrorAndKeepsThePreviousFile) {
  // RLIMIT_FSIZE makes every write beyond the limit fail (EFBIG once SIGXFSZ is ignored): an
  // injected write failure, in a child process so that the limit does not outlive the test.
  const auto dir = test::temporary_dir("atomic_fsize");
  const std::filesystem::path target = dir / "result.bin";
  write_file_atomically(target, "previous");
  const pid_t child = ::fork();
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{4096, 4096};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    try {
      write_file_atomically(target, std::string(100000, 'x'));
    } catch (const AtomicWriteError& e) {
      const std::string what = e.what();
      const bool named = what.find(target.string() + ": not written: writing failed (File too large)") == 0 &&
                         what.find("the previous file is unchanged") != std::string::npos;
      ::_exit(named ? 0 : 2);
    }
    ::_exit(3);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "3: no error; 2: the message did not name the file and the OS error";
  EXPECT_EQ(contents(target), "previous");
  EXPECT_EQ(listing(dir), std::vector<std::string>{"result.bin"});
}

}  // namespace
}  // namespace gpilqg
