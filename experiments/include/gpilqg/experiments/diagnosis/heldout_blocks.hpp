#pragma once
/// @file heldout_blocks.hpp
/// Held-out blocks of one continuous record: blocked cross-validation with a gap.
///
/// A file of several episodes holds whole episodes out (heldout_episodes, transitions.hpp). A file of
/// ONE episode (a continuous log, e.g. 25 s at 1 kHz) has no episodes to hold out, so it is cut into
/// blocks, and the blocks play the part of the episodes:
///
///  - Blocks. The record's T samples are cut into B = kHeldoutBlockCount = 10 contiguous blocks, block b
///    holding the samples [floor(b T / B), floor((b + 1) T / B)) (lengths differ by at most 1).
///  - Held out. The episode rule with B blocks in place of E episodes (heldout_indices): w =
///    round(B f) blocks, clamped to [1, B - 1], f the held-out fraction (--heldout); block b is held out
///    when floor((b + 1) w / B) > floor(b w / B), so they are spread evenly (f = 0.3: blocks 3, 6, 9).
///  - Gap. g = max(max of the k-step horizons, window) samples, `window` being the length of any other
///    window the simulation criterion scores (--window; heldout_block_gap). A training sample s is dropped when a
///    held-out sample h has |s - h| <= g: the g samples on either side of every held-out block are
///    used neither for fitting nor for scoring. So no training sample lies within a k-step window
///    (k <= g) of a held-out sample, and the serial correlation of the residual does not leak the
///    held-out data into the fit. Held-out blocks are kept whole.
///  - Length. Every block must keep training samples after losing g at both ends and hold a k-step
///    window: floor(T / B) >= 2 g + 2, i.e. T >= B (2 g + 2) samples (1020 for the default horizons
///    1, 10, 50). A shorter record is an error naming this need; lower the horizons, or record longer.
///
/// Every step of the diagnosis then treats block b as episode b (block_episodes): the one-step and
/// k-step predictions, the GP and effect fits on the training blocks, the batch-means z score and the
/// delete-one-episode jackknife (batches and replicates never cross a block), the whiteness test
/// (pairs within a block), the free run of every held-out block and --auto's forward selection.

#include <string>
#include <vector>

#include "gpilqg/core/measurements.hpp"

namespace gpilqg::diagnosis {

/// The number of blocks a single-episode record is cut into.
inline constexpr int kHeldoutBlockCount = 10;

/// One block of the record.
struct HeldoutBlock {
  int first = 0;         ///< first sample of the block (0-based, in the record)
  int end = 0;           ///< one past its last sample
  bool heldout = false;
  int used_first = 0;    ///< first sample kept: `first`, or first + gap after a held-out block
  int used_end = 0;      ///< one past the last sample kept: `end`, or end - gap before a held-out block
  double t_start = 0.0;  ///< time of sample `first` [s]
  double t_end = 0.0;    ///< time of sample end - 1 [s]
  int samples() const { return end - first; }
  int used_samples() const { return used_end - used_first; }
};

/// The split of one record.
struct HeldoutBlocks {
  long episode_id = 0;  ///< the record's episode id in the file
  int samples = 0;      ///< T, samples of the record
  int gap = 0;          ///< g [samples]
  double dt = 0.0;      ///< the record's step (gap in seconds = gap * dt)
  std::vector<HeldoutBlock> blocks;
  /// Indices of the held-out blocks, ascending.
  std::vector<int> heldout() const;
};

/// The indices of the held-out items among `count` (episodes or blocks) for held-out fraction f:
/// w = round(count f) clamped to [1, count - 1]; item i is held out when floor((i + 1) w / count) >
/// floor(i w / count). Throws std::invalid_argument when count < 2 or f is outside (0, 1).
std::vector<int> heldout_indices(int count, double fraction);

/// The gap g: the longest window any criterion scores, max(max of `horizons`, `window`). `window` is
/// the hook for a criterion with a window of its own (e.g. a simulation error over a fixed length);
/// 0 when there is none. Throws std::invalid_argument when the result is below 1.
int heldout_block_gap(const std::vector<int>& horizons, int window = 0);

/// Cuts `record` into `count` blocks, holds `fraction` of them out and truncates the training blocks
/// by `gap` (the rule above). Throws std::invalid_argument when the record has fewer than
/// count (2 gap + 2) samples (naming its length, the blocks, the gap and the need), count < 2, gap < 1
/// or fraction is outside (0, 1).
/// `gap_is` says what sets the gap in that message (the diagnosis's longest horizon or its window).
HeldoutBlocks split_heldout_blocks(const Episode& record, double fraction, int gap, int count = kHeldoutBlockCount,
                                   const std::string& gap_is = "the longest k-step horizon");

/// The blocks as episodes: episode b holds the kept samples [used_first, used_end) of block b, id b;
/// `set` must hold the one episode `blocks` was cut from. The system is `set`'s.
MeasurementSet block_episodes(const MeasurementSet& set, const HeldoutBlocks& blocks);

}  // namespace gpilqg::diagnosis
