/// ForkJoin (core/fork_join.hpp): every worker index runs exactly once per run, on distinct threads,
/// across many runs of one pool; the pool grows when asked for more workers; an exception from any
/// worker reaches the caller and leaves the pool usable; copies never share helpers.

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "gpilqg/core/fork_join.hpp"

namespace gpilqg::test {
namespace {

TEST(ForkJoin, OneWorkerRunsOnTheCallingThreadWithoutHelpers) {
  ForkJoin pool;
  std::thread::id ran_on;
  int calls = 0;
  pool.run(1, [&](int worker, int workers) {
    EXPECT_EQ(worker, 0);
    EXPECT_EQ(workers, 1);
    ran_on = std::this_thread::get_id();
    ++calls;
  });
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(ran_on, std::this_thread::get_id());
  EXPECT_EQ(pool.helpers(), 0);
}

TEST(ForkJoin, EveryWorkerRunsOncePerRunOnItsOwnThread) {
  ForkJoin pool;
  for (int run = 0; run < 2000; ++run) {
    std::vector<std::atomic<int>> calls(3);
    std::mutex mutex;
    std::set<std::thread::id> threads;
    pool.run(3, [&](int worker, int workers) {
      EXPECT_EQ(workers, 3);
      ++calls[static_cast<std::size_t>(worker)];
      std::lock_guard lock(mutex);
      threads.insert(std::this_thread::get_id());
    });
    for (const auto& c : calls) ASSERT_EQ(c.load(), 1) << "run " << run;
    ASSERT_EQ(threads.size(), 3u) << "run " << run;
    ASSERT_TRUE(threads.count(std::this_thread::get_id())) << "worker 0 is the caller";
  }
  EXPECT_EQ(pool.helpers(), 2);
}

TEST(ForkJoin, GrowsForMoreWorkersAndLetsSpareHelpersIdle) {
  ForkJoin pool;
  std::atomic<int> sum{0};
  pool.run(2, [&](int worker, int) { sum += worker + 1; });
  EXPECT_EQ(sum.load(), 3);
  EXPECT_EQ(pool.helpers(), 1);
  sum = 0;
  pool.run(4, [&](int worker, int) { sum += worker + 1; });
  EXPECT_EQ(sum.load(), 10);
  EXPECT_EQ(pool.helpers(), 3);
  sum = 0;
  pool.run(2, [&](int worker, int workers) {  // helpers 2 and 3 sit this one out
    EXPECT_EQ(workers, 2);
    sum += worker + 1;
  });
  EXPECT_EQ(sum.load(), 3);
}

TEST(ForkJoin, AnExceptionFromAnyWorkerReachesTheCallerAndThePoolStaysUsable) {
  ForkJoin pool;
  for (int thrower = 0; thrower < 3; ++thrower) {
    std::atomic<int> finished{0};
    try {
      pool.run(3, [&](int worker, int) {
        if (worker == thrower) throw std::runtime_error("worker " + std::to_string(worker));
        ++finished;
      });
      ADD_FAILURE() << "no exception from worker " << thrower;
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "worker " + std::to_string(thrower));
    }
    EXPECT_EQ(finished.load(), 2) << "the other workers still ran to the end";
  }
  // Two workers throw: the lowest-numbered one's exception is reported.
  try {
    pool.run(3, [&](int worker, int) {
      if (worker >= 1) throw std::runtime_error("worker " + std::to_string(worker));
    });
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "worker 1");
  }
  std::atomic<int> calls{0};
  pool.run(3, [&](int, int) { ++calls; });
  EXPECT_EQ(calls.load(), 3) << "no stale error is reported by the next run";
}

TEST(ForkJoin, CopiesStartWithoutHelpers) {
  ForkJoin pool;
  pool.run(2, [](int, int) {});
  ASSERT_EQ(pool.helpers(), 1);
  ForkJoin copy(pool);
  EXPECT_EQ(copy.helpers(), 0);
  ForkJoin assigned;
  assigned = pool;
  EXPECT_EQ(assigned.helpers(), 0);
  EXPECT_EQ(pool.helpers(), 1);
  std::atomic<int> calls{0};
  copy.run(2, [&](int, int) { ++calls; });
  pool.run(2, [&](int, int) { ++calls; });
  EXPECT_EQ(calls.load(), 4);
}

}  // namespace
}  // namespace gpilqg::test
