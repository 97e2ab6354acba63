#pragma once
/// @file mpi_session.hpp
/// The program's view of MPI: which rank this process is, how many there are, and byte messages
/// between them. MPI is started only when an MPI launcher started the process (`mpirun`, `srun`,
/// `mpiexec`: their environment variables tell), so a plain `gpilqg run` never touches MPI. Built
/// without MPI (CMake did not find it), a process that a launcher started more than once refuses to
/// run instead of letting every copy do the whole work.
///
/// Threads: MPI is initialised with MPI_THREAD_SERIALIZED. Rank 0 runs a coordinator thread that
/// makes every MPI call while its main thread works (unit_distribution.hpp); the main thread calls
/// MPI again only after the coordinator has been joined.

#include <optional>
#include <string>
#include <utility>

namespace gpilqg::cli {

/// A message between ranks: who sent it, its tag, its bytes.
struct RankMessage {
  int source = 0;
  int tag = 0;
  std::string bytes;
};

class MpiSession {
 public:
  /// Starts MPI when the process was launched by an MPI launcher with more than one process, else
  /// a session of one rank. Throws std::runtime_error when a launcher asks for several processes and
  /// this program was built without MPI, or when MPI cannot be initialised.
  MpiSession();
  ~MpiSession();  ///< MPI_Finalize when MPI was started
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }
  /// More than one rank: work is spread.
  bool distributed() const { return size_ > 1; }
  /// The ranks on this rank's machine (MPI_COMM_TYPE_SHARED), 1 without MPI.
  int local_size() const { return local_size_; }
  /// The name of this rank's machine.
  const std::string& host() const { return host_; }
  /// Threads each rank may use without oversubscribing its machine: the cores this process may run
  /// on (its CPU affinity), at most the machine's cores divided by the ranks on it, at least 1.
  int threads_per_rank() const;

  void send(int destination, int tag, const std::string& bytes) const;
  /// A waiting message with `tag` from any rank, without blocking.
  std::optional<RankMessage> poll(int tag) const;
  /// Waits for a message with `tag` from any rank, polling (an idle rank must not spin on a core that
  /// another rank computes on).
  RankMessage wait(int tag) const;
  /// A step every rank takes before they work together: each passes its error (empty: it succeeded)
  /// and every rank gets the error of the lowest failing rank, with that rank, or nothing.
  std::optional<std::pair<int, std::string>> first_error(const std::string& error) const;
  /// Rank 0's `text` on every rank.
  std::string broadcast(const std::string& text) const;
  void barrier() const;
  /// Ends every rank of the job at once (MPI_Abort) after printing `why` on stderr: for a broken
  /// conversation between ranks, where waiting would hang the job.
  [[noreturn]] void abort(const std::string& why) const;

 private:
  int rank_ = 0, size_ = 1, local_size_ = 1;
  bool started_ = false;
  std::string host_;
};

}  // namespace gpilqg::cli
