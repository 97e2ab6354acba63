#pragma once
/// @file unit_distribution.hpp
/// Spreads a list of units of work with dependencies over the ranks of an MPI job.
///
/// Rank 0 coordinates and works: a coordinator thread answers the other ranks while rank 0's main
/// thread runs units like any other rank. A rank asks for work, gets the ready unit the
/// UnitScheduler picks (the longest remaining chain first), runs it and reports back; a unit whose
/// dependencies are still running waits until they finish. So ranks never idle while a ready unit
/// waits, and a slow unit delays only the units that need it.
///
/// Stopping. When a unit fails on any rank, or a stop is requested (SIGINT or SIGTERM), no new unit
/// starts, the running units are asked to stop at their next safe point (`stop_requested` answers
/// true; `gpilqg run` then saves the iteration it completed and throws RunInterrupted), and every
/// rank returns the same outcome. What finished stays finished (for `gpilqg run`: in the
/// checkpoint). A rank that dies without reporting (a crash, SIGKILL) ends the whole job through the
/// MPI launcher; the finished work stays in the checkpoint too.
///
/// Protocol (MPI tags kReport: worker -> rank 0; kOrder: rank 0 -> worker, never overtaking each
/// other): a worker sends Ready once, then after each unit Done (with the unit's bytes and wall
/// time), Failed (with the error message and exit status) or Interrupted; rank 0 answers with Assign
/// (a unit), Finish (the outcome) or, to a worker busy when the run stops, Abort.

#include <functional>
#include <string>
#include <vector>

#include "gpilqg/experiments/unit_scheduler.hpp"
#include "mpi_session.hpp"

namespace gpilqg::cli {

/// Runs unit `index` on this rank and returns bytes for rank 0 (empty when everything the unit
/// produced is in shared files). `stop_requested` answers true when the unit should stop at its next
/// safe point. Errors are exceptions: RunInterrupted when it stopped as asked, anything else fails
/// the run (classified as the command line does: bad input exits 2, other errors 1).
using UnitWork = std::function<std::string(int index, const std::function<bool()>& stop_requested)>;

struct Distribution {
  enum class Outcome { Finished, Failed, Interrupted };
  Outcome outcome = Outcome::Finished;
  /// Failed: the exit status the failing unit's error maps to (cli_errors.hpp).
  int failure_exit = 0;
  int failed_rank = -1, failed_unit = -1;
  std::string failure;  ///< Failed: the error message, without the command line's "error: "
  /// Rank 0 only, per unit: the bytes its work returned, the rank that ran it and its wall time [s]
  /// (-1 for a unit that did not finish).
  std::vector<std::string> payloads;
  std::vector<int> ranks;
  std::vector<double> seconds;
};

/// Every rank calls this with the same units (`scheduler` is only consulted on rank 0).
/// `stop_signal` reports a stop request of this process (SIGINT or SIGTERM). On a session of one
/// rank the units simply run in the scheduler's order.
Distribution distribute_units(const MpiSession& session, UnitScheduler& scheduler, const UnitWork& work,
                              const std::function<bool()>& stop_signal);

}  // namespace gpilqg::cli
