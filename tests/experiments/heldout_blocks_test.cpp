// One continuous record (a file of a single episode): blocked cross-validation with a gap
// (heldout_blocks.hpp). The split itself (contiguous blocks, the episode rule for which are held out,
// no training sample within the gap of a held-out one, the error for a short record), then a record
// with hidden Coulomb friction diagnosed end to end, in process and through `gpilqg diagnose --json`
// on a CSV without an episode column, with the blocks named in the reports.

#include <H5Cpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <nlohmann/json.hpp>

#include "diagnosis_support.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"
#include "gpilqg/experiments/diagnosis/heldout_blocks.hpp"
#include "gpilqg/experiments/diagnosis/report.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;
using diagnosis::HeldoutBlock;
using diagnosis::HeldoutBlocks;
using nlohmann::json;

Episode record_of(int samples, double dt = 0.001) {
  Episode e;
  e.id = 4;
  e.t = Vector::LinSpaced(samples, 2.0, 2.0 + (samples - 1) * dt);
  e.x = Matrix::Zero(samples, 4);
  e.x.col(0) = Vector::LinSpaced(samples, 0.0, samples - 1.0);  // x = the sample number, to check copies
  e.u = Matrix::Zero(samples, 1);
  return e;
}

TEST(HeldoutBlocks, AreContiguousSpreadLikeEpisodesAndKeepTheGap) {
  const int T = 2503, gap = 50;
  const HeldoutBlocks split = diagnosis::split_heldout_blocks(record_of(T), 0.3, gap);
  ASSERT_EQ(split.blocks.size(), 10u);
  EXPECT_EQ(split.episode_id, 4);
  EXPECT_EQ(split.samples, T);
  EXPECT_EQ(split.gap, gap);
  // The same rule as for 10 episodes.
  EXPECT_EQ(split.heldout(), (std::vector<int>{3, 6, 9}));
  EXPECT_EQ(split.heldout(), diagnosis::heldout_indices(10, 0.3));
  // Contiguous, covering the record, lengths within one sample of T / 10, times of their samples.
  EXPECT_EQ(split.blocks.front().first, 0);
  EXPECT_EQ(split.blocks.back().end, T);
  for (std::size_t b = 0; b < split.blocks.size(); ++b) {
    const HeldoutBlock& h = split.blocks[b];
    if (b > 0) {
      EXPECT_EQ(h.first, split.blocks[b - 1].end);
    }
    EXPECT_GE(h.samples(), T / 10);
    EXPECT_LE(h.samples(), T / 10 + 1);
    EXPECT_NEAR(h.t_start, 2.0 + h.first * 0.001, 1e-12);
    EXPECT_NEAR(h.t_end, 2.0 + (h.end - 1) * 0.001, 1e-12);
    EXPECT_LE(h.first, h.used_first);
    EXPECT_LE(h.used_end, h.end);
    if (h.heldout) {
      EXPECT_EQ(h.used_samples(), h.samples());  // held-out blocks are whole
    }
  }
  // The gap rule, sample by sample: no kept training sample within `gap` of a held-out sample, and
  // every training sample farther away is kept.
  std::vector<int> role(T, 0);  // 1 held out, 2 kept for training, 0 dropped
  for (const HeldoutBlock& h : split.blocks)
    for (int s = h.used_first; s < h.used_end; ++s) role[static_cast<std::size_t>(s)] = h.heldout ? 1 : 2;
  int dropped = 0;
  for (int s = 0; s < T; ++s) {
    int distance = T;
    for (int h = 0; h < T; ++h)
      if (role[static_cast<std::size_t>(h)] == 1) distance = std::min(distance, std::abs(s - h));
    if (role[static_cast<std::size_t>(s)] == 2) {
      EXPECT_GT(distance, gap) << "sample " << s;
    }
    if (role[static_cast<std::size_t>(s)] == 0) {
      EXPECT_LE(distance, gap) << "sample " << s;
      ++dropped;
    }
  }
  EXPECT_EQ(dropped, 5 * gap);  // blocks 2, 4, 5, 7 and 8 border held-out blocks 3, 6, 9
  // A smaller fraction still holds one block out, a larger one leaves one for training.
  EXPECT_EQ(diagnosis::split_heldout_blocks(record_of(T), 0.01, gap).heldout(), (std::vector<int>{9}));
  EXPECT_EQ(diagnosis::split_heldout_blocks(record_of(T), 0.99, gap).heldout().size(), 9u);
}

TEST(HeldoutBlocks, GapIsTheLongestWindowAndTheRecordMustHoldTheBlocks) {
  EXPECT_EQ(diagnosis::heldout_block_gap({1, 10, 50}), 50);
  EXPECT_EQ(diagnosis::heldout_block_gap({1, 10, 50}, 80), 80);  // a longer window of another criterion
  EXPECT_EQ(diagnosis::heldout_block_gap({5}, 2), 5);
  // 10 blocks of at least 2 gap + 2 samples: 1020 for a gap of 50.
  EXPECT_NO_THROW(diagnosis::split_heldout_blocks(record_of(1020), 0.3, 50));
  try {
    diagnosis::split_heldout_blocks(record_of(1019), 0.3, 50);
    FAIL() << "a record too short for its blocks was accepted";
  } catch (const diagnosis::DataProblem& e) {  // the data's, named with its file
    const std::string message = e.what();
    for (const char* part : {"1 episode of 1019 samples", "expected at least 1020 samples", "10 blocks", "102 samples",
                             "gap of 50 samples (the longest k-step horizon)", "shorten the longest k-step horizon"})
      EXPECT_NE(message.find(part), std::string::npos) << part << " in: " << message;
  }
}

TEST(HeldoutBlocks, BecomeEpisodesOfTheirKeptSamples) {
  MeasurementSet set;
  set.system = system_signature("cartpole");
  set.episodes.push_back(record_of(1100));
  const HeldoutBlocks split = diagnosis::split_heldout_blocks(set.episodes[0], 0.3, 20);
  const MeasurementSet blocks = diagnosis::block_episodes(set, split);
  ASSERT_EQ(blocks.episodes.size(), 10u);
  for (std::size_t b = 0; b < 10; ++b) {
    const Episode& e = blocks.episodes[b];
    const HeldoutBlock& h = split.blocks[b];
    EXPECT_EQ(e.id, static_cast<long>(b));
    ASSERT_EQ(e.length(), h.used_samples());
    EXPECT_EQ(e.x(0, 0), h.used_first);
    EXPECT_EQ(e.x(e.length() - 1, 0), h.used_end - 1);
    EXPECT_EQ(e.t(0), set.episodes[0].t(h.used_first));
  }
  // Transitions never cross a block: every one steps to the next sample of the record.
  const auto data = diagnosis::make_transitions(blocks, split.heldout(), 0.001);
  for (int i = 0; i < data.size(); ++i) EXPECT_EQ(data.x_next(i, 0), data.x(i, 0) + 1.0);
}

/// One continuous record of the cart-pole with hidden Coulomb friction: 1200 samples (24 s), one
/// episode, the multi-episode tests' noise.
MeasurementSet friction_record(double mu, std::uint64_t seed) {
  ModelSpec world;
  world.system = "cartpole";
  world = world.with(find_effect("cartpole", "cart_coulomb_friction"), Vector::Constant(1, mu));
  const DynamicsPtr system = world.build(test::actuator_noise(1, 0.02));
  ExcitationSettings settings = default_excitation(*system);
  settings.episodes = 1;
  settings.steps = 1200;
  settings.seed = seed;
  return simulate_measurements(system, settings).set;
}

/// The friction of 1 N is named, fitted within 15%, and explains more than 30% of the held-out residual.
void expect_friction_found(const diagnosis::DiagnosisReport& r) {
  ASSERT_EQ(r.verdict.status, "explained") << r.verdict.reason;
  ASSERT_EQ(r.verdict.effect->effect, "cart_coulomb_friction");
  EXPECT_NEAR(r.verdict.effect->estimate(0), 1.0, 0.15);
  const int worst = diagnosis::worst_state(r);
  EXPECT_LT(r.verdict.effect->heldout_rmse_after(worst), 0.8 * r.verdict.effect->heldout_rmse_before(worst));
  EXPECT_GT(r.verdict.effect->explained, 0.3);
}

// The multi-episode tests' seeds and tolerance (diagnosis_test.cpp): named, within 15%, error falls.
TEST(HeldoutBlocks, OneRecordWithHiddenFrictionIsFoundLikeInEpisodes) {
  for (std::uint64_t seed : {22, 33}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    expect_friction_found(diagnosis::diagnose(friction_record(1.0, seed), test::fast_options("cartpole")));
  }
}

TEST(HeldoutBlocks, OneRecordWithHiddenFrictionIsDiagnosedPerBlock) {
  const MeasurementSet data = friction_record(1.0, 11);
  ASSERT_EQ(data.episodes.size(), 1u);
  const diagnosis::DiagnosisReport r = diagnosis::diagnose(data, test::fast_options("cartpole"));
  ASSERT_TRUE(r.blocks.has_value());
  EXPECT_EQ(r.blocks->gap, 50);
  EXPECT_EQ(r.heldout_episode_index, (std::vector<int>{3, 6, 9}));
  EXPECT_EQ(r.heldout_episode_ids, (std::vector<long>{3, 6, 9}));
  expect_friction_found(r);
  // Blocks of 1200 / 10 = 120 samples, 5 gaps of 50 samples dropped, one transition fewer than samples per block.
  EXPECT_EQ(r.samples, 1200 - 5 * 50 - 10);
  // Every step per block: the free run of each held-out block, residual per block.
  ASSERT_EQ(r.free_run.size(), 3u);
  EXPECT_EQ(r.free_run[0].id, 3);
  EXPECT_EQ(r.free_run[0].t.size(), 120);
  EXPECT_EQ(r.episode_rms.rows(), 10);
  // No training transition within the gap of a held-out one (times: dt = 0.02 s).
  const double dt = r.dt, gap_time = r.blocks->gap * dt;
  for (int i : r.data.rows(false))
    for (int h : r.data.rows(true)) ASSERT_GT(std::abs(r.data.t(i) - r.data.t(h)), gap_time + 0.5 * dt);
  const json j = diagnosis::report_json(r);
  EXPECT_EQ(j["heldout_blocks"]["heldout"], json({3, 6, 9}));
  const std::string text = diagnosis::report_text(r);
  EXPECT_NE(text.find("cut into 10 blocks, held-out blocks 3, 6, 9"), std::string::npos) << text;
}

// Through the command: a CSV with no episode column, the JSON naming the blocks; and the error for a
// record too short for the blocks and their gaps.
TEST(HeldoutBlocksCli, DiagnoseCliReadsARecordWithoutEpisodeColumnAndNamesTheBlocks) {
  const fs::path dir = test::temporary_dir("heldout_blocks_cli");
  const fs::path with_column = dir / "with_column.csv", record = dir / "record.csv", report = dir / "report.h5";
  write_measurements(with_column, friction_record(1.2, 5));
  {
    // The same rows without the leading `episode,` / `0,` field.
    std::ifstream in(with_column);
    std::ofstream out(record);
    for (std::string line; std::getline(in, line);) out << line.substr(line.find(',') + 1) << "\n";
  }
  const auto result = test::run_cli("diagnose --system cartpole --data '" + record.string() +
                                    "' --json --out '" + report.string() + "' --gp-points 100 --gp-restarts 0");
  ASSERT_EQ(result.status, 0) << result.err;
  const json j = json::parse(result.out);
  EXPECT_EQ(j["verdict"]["effect"], "cart_coulomb_friction");
  EXPECT_NEAR(j["verdict"]["parameters"]["mu"].get<double>(), 1.2, 0.18);
  EXPECT_EQ(j["heldout_episodes"], json({3, 6, 9}));
  const json& blocks = j["heldout_blocks"];
  EXPECT_EQ(blocks["episode"], 0);
  EXPECT_EQ(blocks["samples"], 1200);
  EXPECT_EQ(blocks["count"], 10);
  EXPECT_EQ(blocks["gap"], 50);
  EXPECT_NEAR(blocks["gap_time"].get<double>(), 1.0, 1e-12);
  ASSERT_EQ(blocks["blocks"].size(), 10u);
  const json& b2 = blocks["blocks"][2];  // a training block before held-out block 3
  EXPECT_EQ(b2["heldout"], false);
  EXPECT_EQ(b2["first"], 240);
  EXPECT_EQ(b2["last"], 359);
  EXPECT_NEAR(b2["t_start"].get<double>(), 4.8, 1e-9);
  EXPECT_NEAR(b2["t_end"].get<double>(), 7.18, 1e-9);
  EXPECT_EQ(b2["used_first"], 240);
  EXPECT_EQ(b2["used_last"], 309);
  EXPECT_EQ(b2["dropped"], 50);
  EXPECT_EQ(blocks["blocks"][3]["heldout"], true);
  EXPECT_EQ(blocks["blocks"][3]["dropped"], 0);
  EXPECT_EQ(j["free_run"].size(), 3u);
  {
    H5::H5File h5(report.string(), H5F_ACC_RDONLY);
    std::vector<double> heldout(10), used_first(10);
    h5.openDataSet("/heldout_blocks/heldout").read(heldout.data(), H5::PredType::NATIVE_DOUBLE);
    h5.openDataSet("/heldout_blocks/used_first").read(used_first.data(), H5::PredType::NATIVE_DOUBLE);
    EXPECT_EQ(heldout, (std::vector<double>{0, 0, 0, 1, 0, 0, 1, 0, 0, 1}));
    EXPECT_EQ(used_first[4], 530.0);  // block 4 starts at 480, after held-out block 3
    std::int64_t gap = 0;
    h5.openGroup("/heldout_blocks").openAttribute("gap").read(H5::PredType::NATIVE_INT64, &gap);
    EXPECT_EQ(gap, 50);
  }

  const auto short_record = test::run_cli("diagnose --system cartpole --data '" + record.string() +
                                          "' --horizons 1,80 --json --gp-points 100 --gp-restarts 0");
  EXPECT_EQ(short_record.status, 2);
  EXPECT_NE(short_record.err.find("expected at least 1620 samples"), std::string::npos) << short_record.err;
}

}  // namespace
}  // namespace gpilqg
