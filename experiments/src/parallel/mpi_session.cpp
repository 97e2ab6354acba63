#include "mpi_session.hpp"

#include <sched.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#ifdef GPILQG_WITH_MPI
#include <mpi.h>
#endif

namespace gpilqg::cli {
namespace {

/// How long an idle rank sleeps between looks at its mailbox: short against units of seconds,
/// long enough that waiting costs no measurable CPU.
constexpr auto kPollInterval = std::chrono::milliseconds(2);

/// The number of processes an MPI launcher started, from its environment (Open MPI's mpirun, PMIx
/// and PMI as srun and MPICH's hydra set them); 1 when no launcher started this process.
int launched_processes() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_SIZE", "PMI_SIZE", "MPI_LOCALNRANKS"})
    if (const char* value = std::getenv(name)) return std::max(1, std::atoi(value));
  // PMIx does not always export a size; its rank variable alone says a launcher is there.
  return std::getenv("PMIX_RANK") != nullptr ? 2 : 1;
}

std::string host_name() {
  char buffer[256] = {};
  return gethostname(buffer, sizeof buffer - 1) == 0 ? std::string(buffer) : std::string("?");
}

#ifdef GPILQG_WITH_MPI
void check(int code, const char* call) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING] = {};
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw std::runtime_error(fmt::format("{} failed: {}", call, std::string(text, static_cast<std::size_t>(length))));
}
#endif

}  // namespace

MpiSession::MpiSession() : host_(host_name()) {
  if (launched_processes() <= 1) return;
#ifdef GPILQG_WITH_MPI
  int provided = 0;
  check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided), "MPI_Init_thread");
  if (provided < MPI_THREAD_SERIALIZED) {
    MPI_Finalize();  // the destructor of a constructor that throws does not run
    throw std::runtime_error("the MPI library does not support MPI_THREAD_SERIALIZED, which gpilqg needs");
  }
  try {
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    check(MPI_Comm_rank(MPI_COMM_WORLD, &rank_), "MPI_Comm_rank");
    check(MPI_Comm_size(MPI_COMM_WORLD, &size_), "MPI_Comm_size");
    MPI_Comm local;
    check(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &local), "MPI_Comm_split_type");
    MPI_Comm_size(local, &local_size_);
    MPI_Comm_free(&local);
  } catch (...) {
    MPI_Finalize();
    throw;
  }
  started_ = true;
#else
  throw std::runtime_error(
      "an MPI launcher started several gpilqg processes, but this gpilqg was built without MPI (install "
      "libopenmpi-dev and rebuild; docs/cluster.md); every process would repeat the whole work");
#endif
}

MpiSession::~MpiSession() {
#ifdef GPILQG_WITH_MPI
  if (started_) MPI_Finalize();
#endif
}

int MpiSession::threads_per_rank() const {
  const int machine = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  int allowed = machine;
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) allowed = std::max(1, CPU_COUNT(&set));
  // The cores it may use, but no more than its share of the machine: ranks bound to a shared set (a
  // socket, a SLURM cpuset) must not each take the whole set.
  return std::max(1, std::min(allowed, machine / local_size_));
}

#ifdef GPILQG_WITH_MPI

void MpiSession::send(int destination, int tag, const std::string& bytes) const {
  check(MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, destination, tag, MPI_COMM_WORLD), "MPI_Send");
}

std::optional<RankMessage> MpiSession::poll(int tag) const {
  int waiting = 0;
  MPI_Status status;
  check(MPI_Iprobe(MPI_ANY_SOURCE, tag, MPI_COMM_WORLD, &waiting, &status), "MPI_Iprobe");
  if (!waiting) return std::nullopt;
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  RankMessage message{status.MPI_SOURCE, tag, std::string(static_cast<std::size_t>(count), '\0')};
  check(MPI_Recv(message.bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
        "MPI_Recv");
  return message;
}

namespace {

/// `text` of rank `root` on every rank.
std::string broadcast_from(int root, int rank, const std::string& text) {
  long long length = static_cast<long long>(text.size());
  check(MPI_Bcast(&length, 1, MPI_LONG_LONG, root, MPI_COMM_WORLD), "MPI_Bcast");
  std::string out = rank == root ? text : std::string(static_cast<std::size_t>(length), '\0');
  check(MPI_Bcast(out.data(), static_cast<int>(length), MPI_BYTE, root, MPI_COMM_WORLD), "MPI_Bcast");
  return out;
}

}  // namespace

std::string MpiSession::broadcast(const std::string& text) const {
  return started_ ? broadcast_from(0, rank_, text) : text;
}

std::optional<std::pair<int, std::string>> MpiSession::first_error(const std::string& error) const {
  if (!started_) return error.empty() ? std::nullopt : std::optional(std::pair(0, error));
  int mine = error.empty() ? size_ : rank_, first = size_;
  check(MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD), "MPI_Allreduce");
  if (first == size_) return std::nullopt;
  return std::pair(first, broadcast_from(first, rank_, error));
}

void MpiSession::barrier() const {
  if (started_) check(MPI_Barrier(MPI_COMM_WORLD), "MPI_Barrier");
}

void MpiSession::abort(const std::string& why) const {
  std::fprintf(stderr, "internal error: rank %d of %d: %s\n", rank_, size_, why.c_str());
  std::fflush(stderr);
  if (started_) MPI_Abort(MPI_COMM_WORLD, 1);
  std::abort();
}

#else

void MpiSession::abort(const std::string& why) const {
  std::fprintf(stderr, "internal error: %s\n", why.c_str());
  std::abort();
}

void MpiSession::send(int, int, const std::string&) const {
  throw std::logic_error("MpiSession::send: a session of one rank has no one to send to");
}
std::optional<RankMessage> MpiSession::poll(int) const { return std::nullopt; }
std::string MpiSession::broadcast(const std::string& text) const { return text; }
std::optional<std::pair<int, std::string>> MpiSession::first_error(const std::string& error) const {
  return error.empty() ? std::nullopt : std::optional(std::pair(0, error));
}
void MpiSession::barrier() const {}

#endif

RankMessage MpiSession::wait(int tag) const {
  if (!distributed()) throw std::logic_error("MpiSession::wait: a session of one rank receives nothing");
  for (;;) {
    if (auto message = poll(tag)) return std::move(*message);
    std::this_thread::sleep_for(kPollInterval);
  }
}

}  // namespace gpilqg::cli
