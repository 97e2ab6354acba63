#include "gpilqg/experiments/diagnosis/heldout_blocks.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include "gpilqg/experiments/diagnosis/data_problem.hpp"

namespace gpilqg::diagnosis {

std::vector<int> HeldoutBlocks::heldout() const {
  std::vector<int> out;
  for (std::size_t b = 0; b < blocks.size(); ++b)
    if (blocks[b].heldout) out.push_back(static_cast<int>(b));
  return out;
}

std::vector<int> heldout_indices(int count, double fraction) {
  if (count < 2) throw std::invalid_argument(fmt::format("{} item(s) to hold out from; expected at least 2", count));
  if (!(fraction > 0.0 && fraction < 1.0))
    throw std::invalid_argument("held-out fraction " + std::to_string(fraction) + "; expected a value in (0, 1)");
  const int wanted = std::clamp(static_cast<int>(std::lround(count * fraction)), 1, count - 1);
  // Spread evenly: item i is held out when floor((i + 1) w / count) > floor(i w / count).
  std::vector<int> out;
  for (int i = 0; i < count; ++i)
    if (((i + 1) * wanted) / count > (i * wanted) / count) out.push_back(i);
  return out;
}

int heldout_block_gap(const std::vector<int>& horizons, int window) {
  int gap = window;
  for (int k : horizons) gap = std::max(gap, k);
  if (gap < 1) throw std::invalid_argument(fmt::format("held-out block gap {}; expected at least 1 sample", gap));
  return gap;
}

HeldoutBlocks split_heldout_blocks(const Episode& record, double fraction, int gap, int count, const std::string& gap_is) {
  if (count < 2) throw std::invalid_argument(fmt::format("{} held-out block(s); expected at least 2", count));
  if (gap < 1) throw std::invalid_argument(fmt::format("held-out block gap {}; expected at least 1 sample", gap));
  const int T = record.length();
  const long needed = static_cast<long>(count) * (2L * gap + 2L);
  if (T < needed)
    throw DataProblem(fmt::format(
        "the data has 1 episode of {} samples; expected at least {} samples, since a single record is cut into {} "
        "blocks for held-out scoring, each of at least 2 x gap + 2 = {} samples with a gap of {} samples ({}) dropped "
        "on either side of every held-out block; record longer, shorten {}, or give several episodes",
        T, needed, count, 2 * gap + 2, gap, gap_is, gap_is));
  HeldoutBlocks out;
  out.episode_id = record.id;
  out.samples = T;
  out.gap = gap;
  out.dt = record.dt();
  const std::vector<int> held = heldout_indices(count, fraction);
  for (int b = 0; b < count; ++b) {
    HeldoutBlock block;
    block.first = static_cast<int>(static_cast<long>(b) * T / count);
    block.end = static_cast<int>(static_cast<long>(b + 1) * T / count);
    block.heldout = std::find(held.begin(), held.end(), b) != held.end();
    block.t_start = record.t(block.first);
    block.t_end = record.t(block.end - 1);
    out.blocks.push_back(block);
  }
  // A training sample s is dropped when a held-out sample h has |s - h| <= gap. Blocks are at least
  // 2 gap + 2 long, so only the held-out neighbours of a block can reach into it.
  for (int b = 0; b < count; ++b) {
    HeldoutBlock& block = out.blocks[static_cast<std::size_t>(b)];
    block.used_first = block.first;
    block.used_end = block.end;
    if (block.heldout) continue;
    if (b > 0 && out.blocks[static_cast<std::size_t>(b - 1)].heldout) block.used_first += gap;
    if (b + 1 < count && out.blocks[static_cast<std::size_t>(b + 1)].heldout) block.used_end -= gap;
  }
  return out;
}

MeasurementSet block_episodes(const MeasurementSet& set, const HeldoutBlocks& blocks) {
  if (set.episodes.size() != 1 || set.episodes.front().length() != blocks.samples)
    throw std::invalid_argument(fmt::format("block_episodes: the set has {} episode(s); expected the one record of {} "
                                            "samples the blocks were cut from",
                                            set.episodes.size(), blocks.samples));
  const Episode& record = set.episodes.front();
  MeasurementSet out;
  out.system = set.system;
  out.estimated_states = set.estimated_states;
  for (std::size_t b = 0; b < blocks.blocks.size(); ++b) {
    const HeldoutBlock& block = blocks.blocks[b];
    const int length = block.used_samples();
    Episode e;
    e.id = static_cast<long>(b);
    e.t = record.t.segment(block.used_first, length);
    e.x = record.x.middleRows(block.used_first, length);
    e.u = record.u.middleRows(block.used_first, length);
    out.episodes.push_back(std::move(e));
  }
  return out;
}

}  // namespace gpilqg::diagnosis
