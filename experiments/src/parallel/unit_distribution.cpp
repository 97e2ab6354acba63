#include "unit_distribution.hpp"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/run_checkpoint.hpp"

namespace gpilqg::cli {
namespace {

constexpr int kReport = 1;
constexpr int kOrder = 2;
constexpr auto kCoordinatorInterval = std::chrono::milliseconds(2);

enum class Kind : std::int32_t { Ready, Done, Failed, Interrupted, Assign, Finish, Abort };

/// A message: its kind, a unit, a status and a time, then free bytes (payload or error text).
struct Message {
  Kind kind = Kind::Ready;
  std::int32_t unit = -1;
  std::int32_t code = 0;
  double seconds = 0.0;
  std::string bytes;
};

constexpr std::size_t kHeader = 3 * sizeof(std::int32_t) + sizeof(double);

std::string encode(const Message& m) {
  std::string out(kHeader, '\0');
  const auto kind = static_cast<std::int32_t>(m.kind);
  std::memcpy(out.data(), &kind, 4);
  std::memcpy(out.data() + 4, &m.unit, 4);
  std::memcpy(out.data() + 8, &m.code, 4);
  std::memcpy(out.data() + 12, &m.seconds, 8);
  return out + m.bytes;
}

Message decode(const std::string& bytes) {
  if (bytes.size() < kHeader) throw std::runtime_error("unit distribution: a message shorter than its header");
  Message m;
  std::int32_t kind = 0;
  std::memcpy(&kind, bytes.data(), 4);
  std::memcpy(&m.unit, bytes.data() + 4, 4);
  std::memcpy(&m.code, bytes.data() + 8, 4);
  std::memcpy(&m.seconds, bytes.data() + 12, 8);
  m.kind = static_cast<Kind>(kind);
  m.bytes = bytes.substr(kHeader);
  return m;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Runs one unit and turns its end into a report: Done with its bytes, Interrupted, or Failed with
/// the message and exit status the command line would give its error.
Message run_one(const UnitWork& work, int unit, const std::function<bool()>& stop_requested) {
  const auto start = std::chrono::steady_clock::now();
  Message report{Kind::Done, unit, 0, 0.0, {}};
  try {
    report.bytes = work(unit, stop_requested);
  } catch (const RunInterrupted& e) {
    report.kind = Kind::Interrupted;
    report.bytes = e.what();
  } catch (...) {
    const DescribedError error = describe_error(std::current_exception());
    report.kind = Kind::Failed;
    report.code = error.exit_status;
    report.bytes = error.detail;
  }
  report.seconds = seconds_since(start);
  return report;
}

/// Rank 0's shared state: the scheduler, who runs what, and whether the run is stopping.
class Coordinator {
 public:
  Coordinator(const MpiSession& session, UnitScheduler& scheduler) : session_(session), scheduler_(scheduler) {
    const auto ranks = static_cast<std::size_t>(session.size());
    busy_.assign(ranks, -1);
    waiting_.assign(ranks, false);
    finished_.assign(ranks, false);
    aborted_.assign(ranks, false);
    result_.payloads.assign(static_cast<std::size_t>(scheduler.size()), {});
    result_.ranks.assign(static_cast<std::size_t>(scheduler.size()), -1);
    result_.seconds.assign(static_cast<std::size_t>(scheduler.size()), -1.0);
  }

  /// Rank 0's own next unit: waits until one is ready; nothing when the run is over or stopping.
  std::optional<int> take_local() {
    std::unique_lock lock(mutex_);
    for (;;) {
      if (stopping_ || scheduler_.all_finished()) return std::nullopt;
      if (auto unit = scheduler_.next()) {
        busy_[0] = *unit;
        return unit;
      }
      changed_.wait(lock);
    }
  }

  bool stopping() const { return stopping_.load(); }

  void report(int rank, const Message& m) {
    std::lock_guard lock(mutex_);
    handle(rank, m);
    changed_.notify_all();
  }

  void stop(Distribution::Outcome why) {
    std::lock_guard lock(mutex_);
    begin_stop(why);
    changed_.notify_all();
  }

  /// The coordinator thread: answers the other ranks until every one has been told to finish.
  void serve(const std::function<bool()>& stop_signal) {
    for (;;) {
      while (auto message = session_.poll(kReport)) report(message->source, decode(message->bytes));
      if (stop_signal() && !stopping_) stop(Distribution::Outcome::Interrupted);
      {
        std::lock_guard lock(mutex_);
        dispatch();
        if (std::all_of(finished_.begin() + 1, finished_.end(), [](bool f) { return f; })) return;
      }
      std::this_thread::sleep_for(kCoordinatorInterval);
    }
  }

  Distribution result() {
    std::lock_guard lock(mutex_);
    return result_;
  }

 private:
  void handle(int rank, const Message& m) {
    const auto r = static_cast<std::size_t>(rank);
    if (m.kind != Kind::Ready) {
      if (busy_[r] != m.unit) throw std::logic_error("unit distribution: a report for a unit the rank was not given");
      busy_[r] = -1;
    }
    switch (m.kind) {
      case Kind::Ready:
        break;
      case Kind::Done:
        scheduler_.finished(m.unit);
        result_.payloads[static_cast<std::size_t>(m.unit)] = m.bytes;
        result_.ranks[static_cast<std::size_t>(m.unit)] = rank;
        result_.seconds[static_cast<std::size_t>(m.unit)] = m.seconds;
        break;
      case Kind::Failed:
        scheduler_.requeue(m.unit);
        if (!stopping_) {
          result_.failed_rank = rank, result_.failed_unit = m.unit;
          result_.failure = m.bytes, result_.failure_exit = m.code;
        }
        begin_stop(Distribution::Outcome::Failed);
        break;
      case Kind::Interrupted:
        scheduler_.requeue(m.unit);
        begin_stop(Distribution::Outcome::Interrupted);
        break;
      default:
        throw std::logic_error("unit distribution: rank 0 received an order");
    }
    if (rank != 0) waiting_[r] = true;
  }

  /// The first reason to stop wins. (Called from either thread: the messages go out in dispatch.)
  void begin_stop(Distribution::Outcome why) {
    if (stopping_ || scheduler_.all_finished()) return;  // a stop after the last unit changes nothing
    stopping_ = true;
    result_.outcome = why;
  }

  /// Gives each waiting rank a ready unit, or tells it to finish when nothing is left to start; when
  /// the run stops, asks each busy rank to stop at its next safe point. Coordinator thread only. The
  /// blocking sends under the mutex cannot wait on a worker: orders are a few bytes (sent eagerly),
  /// and a busy worker is only ever sent Abort.
  void dispatch() {
    for (std::size_t r = 1; r < busy_.size(); ++r)
      if (stopping_ && busy_[r] >= 0 && !aborted_[r]) {
        session_.send(static_cast<int>(r), kOrder, encode({Kind::Abort, busy_[r], 0, 0.0, {}}));
        aborted_[r] = true;
      }
    for (std::size_t r = 1; r < waiting_.size(); ++r) {
      if (!waiting_[r] || finished_[r]) continue;
      if (stopping_ || scheduler_.all_finished()) {
        const int code = result_.outcome == Distribution::Outcome::Failed ? result_.failure_exit : 0;
        session_.send(static_cast<int>(r), kOrder, encode({Kind::Finish, static_cast<std::int32_t>(result_.outcome), code, 0.0, {}}));
        finished_[r] = true, waiting_[r] = false;
      } else if (auto unit = scheduler_.next()) {
        session_.send(static_cast<int>(r), kOrder, encode({Kind::Assign, *unit, 0, 0.0, {}}));
        busy_[r] = *unit, waiting_[r] = false, aborted_[r] = false;
      }
    }
  }

  const MpiSession& session_;
  UnitScheduler& scheduler_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::atomic<bool> stopping_{false};
  std::vector<int> busy_;
  std::vector<bool> waiting_, finished_, aborted_;
  Distribution result_;
};

Distribution run_root(const MpiSession& session, UnitScheduler& scheduler, const UnitWork& work,
                      const std::function<bool()>& stop_signal) {
  Coordinator coordinator(session, scheduler);
  std::thread thread([&] {
    try {
      coordinator.serve(stop_signal);
    } catch (const std::exception& e) {
      // The other ranks wait for orders that will not come: end the whole job.
      session.abort(fmt::format("rank 0's coordinator failed: {}", e.what()));
    }
  });
  const std::function<bool()> stop_requested = [&] { return coordinator.stopping() || stop_signal(); };
  while (auto unit = coordinator.take_local()) coordinator.report(0, run_one(work, *unit, stop_requested));
  thread.join();
  return coordinator.result();
}

Distribution serve_as_worker(const MpiSession& session, const UnitWork& work, const std::function<bool()>& stop_signal) {
  session.send(0, kReport, encode({Kind::Ready, -1, 0, 0.0, {}}));
  for (;;) {
    const Message order = decode(session.wait(kOrder).bytes);
    if (order.kind == Kind::Abort) continue;  // for a unit that finished before the request arrived
    if (order.kind == Kind::Finish) {
      Distribution result;
      result.outcome = static_cast<Distribution::Outcome>(order.unit);
      result.failure_exit = order.code;
      return result;
    }
    if (order.kind != Kind::Assign) throw std::logic_error("unit distribution: a worker received a report");
    bool aborted = false;
    const std::function<bool()> stop_requested = [&] {
      if (!aborted)
        if (auto message = session.poll(kOrder)) {
          if (decode(message->bytes).kind != Kind::Abort)
            throw std::logic_error("unit distribution: an order other than Abort while a unit runs");
          aborted = true;
        }
      return aborted || stop_signal();
    };
    session.send(0, kReport, encode(run_one(work, order.unit, stop_requested)));
  }
}

/// A worker whose conversation with rank 0 breaks (an MPI error, a message it cannot read) ends the
/// job: rank 0 would wait for its report forever.
Distribution run_worker(const MpiSession& session, const UnitWork& work, const std::function<bool()>& stop_signal) {
  try {
    return serve_as_worker(session, work, stop_signal);
  } catch (const std::exception& e) {
    session.abort(fmt::format("rank {} lost its coordinator: {}", session.rank(), e.what()));
  }
}

}  // namespace

Distribution distribute_units(const MpiSession& session, UnitScheduler& scheduler, const UnitWork& work,
                              const std::function<bool()>& stop_signal) {
  if (!session.distributed()) {
    Distribution result;
    result.payloads.assign(static_cast<std::size_t>(scheduler.size()), {});
    result.ranks.assign(static_cast<std::size_t>(scheduler.size()), 0);
    result.seconds.assign(static_cast<std::size_t>(scheduler.size()), -1.0);
    while (auto unit = scheduler.next()) {
      const auto start = std::chrono::steady_clock::now();
      result.payloads[static_cast<std::size_t>(*unit)] = work(*unit, stop_signal);
      result.seconds[static_cast<std::size_t>(*unit)] = seconds_since(start);
      scheduler.finished(*unit);
    }
    return result;
  }
  return session.is_root() ? run_root(session, scheduler, work, stop_signal) : run_worker(session, work, stop_signal);
}

}  // namespace gpilqg::cli
