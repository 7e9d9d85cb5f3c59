// arwb lab --shard K/N and --merge: a run spread over separate processes, joined, is the single run; the parts
// that cannot be joined (one missing, one of another run) and a bad K/N are named.
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace arwb {
namespace {

using test::run_arwb;
using test::TempDir;

using test::line_count;
using test::read_file;

// table.csv without its last column (median_ms, the one that varies from run to run).
std::string without_times(const std::string& csv) {
  std::string out;
  std::istringstream in(csv);
  for (std::string line; std::getline(in, line);) out += line.substr(0, line.rfind(',')) + "\n";
  return out;
}

// results.json without the run's and the detectors' times.
nlohmann::json json_without_times(const std::string& path) {
  nlohmann::json j = nlohmann::json::parse(read_file(path), nullptr, false);
  if (!j.is_object()) return j;
  j.erase("seconds");
  for (auto& cell : j["cells"])
    for (auto& [name, result] : cell["results"].items()) result.erase("median_ms");
  return j;
}

TEST(LabShards, ThreePartsInSeparateProcessesMergeIntoTheSingleRun) {
  TempDir d;
  const std::string options = "lab --frames-per-cell 2 --detectors arwb,opencv";
  const auto one = run_arwb(options + " --out " + d.str("one"));
  ASSERT_EQ(one.status, 0) << one.err;
  // The three parts at once, each its own arwb, as a cluster's tasks would be.
  std::string parts;
  for (int k = 1; k <= 3; ++k) parts += " " + d.str("part" + std::to_string(k));
  const std::string shards = "for k in 1 2 3; do '" + std::string(ARWB_BINARY) + "' " + options +
                             " --shard $k/3 --out " + d.str("part") + "$k >" + d.str("out") +
                             "$k.txt 2>&1 & done; wait";
  ASSERT_EQ(std::system(shards.c_str()), 0) << shards;
  for (int k = 1; k <= 3; ++k) {
    const std::string k_text = std::to_string(k);
    const std::string printed = read_file(d.str("out" + k_text + ".txt"));
    // Every third of the 27 cells and the curves' 8: 12, 12 and 11.
    const std::string cells = k < 3 ? "12" : "11";
    EXPECT_EQ(printed.rfind("Part " + k_text + " of 3 of the paper's plan: " + cells + " of 35 cells in ", 0), 0u)
        << printed;
    EXPECT_EQ(line_count(read_file(d.str("part" + k_text + "/cells.jsonl"))), k < 3 ? 12u : 11u);
  }
  const auto merged = run_arwb(options + " --merge" + parts + " --out " + d.str("all"));
  ASSERT_EQ(merged.status, 0) << merged.err;
  EXPECT_NE(merged.out.find("merged from 3 parts; its cells took "), std::string::npos) << merged.out;
  EXPECT_EQ(read_file(d.str("all/table.txt")), read_file(d.str("one/table.txt")));
  EXPECT_EQ(without_times(read_file(d.str("all/table.csv"))), without_times(read_file(d.str("one/table.csv"))));
  EXPECT_EQ(json_without_times(d.str("all/results.json")), json_without_times(d.str("one/results.json")));
  EXPECT_EQ(line_count(read_file(d.str("all/cells.jsonl"))), 35u) << "the merged folder holds every cell";
  EXPECT_GT(read_file(d.str("all/report.pdf")).size(), 1000u);

  // A part missing: its cells are named, nothing is written.
  const auto two = run_arwb(options + " --merge " + d.str("part1") + " " + d.str("part2") + " --out " + d.str("x"));
  EXPECT_EQ(two.status, 1);
  EXPECT_NE(two.err.find("--merge: 11 of 35 cells are in none of the folders: cell 3 (65 mm, 2.0 m, 500 lx), cell 6 "
                         "(65 mm, 1.0 m, 500 lx), cell 9 (65 mm, 0.5 m, 500 lx), ...; run the parts that hold them"),
            std::string::npos)
      << two.err;
  EXPECT_FALSE(std::ifstream(d.str("x/table.txt")).good());
  // Parts of another run (the merge forgot --seed, or the frames): what differs is said.
  const auto seed = run_arwb(options + " --seed 2 --merge" + parts);
  EXPECT_EQ(seed.status, 1);
  EXPECT_NE(seed.err.find(d.str("part1/cells.jsonl") + ": its cells are of another run (its seed is 1, this run's 2)"),
            std::string::npos)
      << seed.err;
  const auto frames = run_arwb("lab --frames-per-cell 3 --detectors arwb,opencv --merge" + parts);
  EXPECT_NE(frames.err.find("(its plan's frames_per_cell is 2, this run's 3)"), std::string::npos) << frames.err;
  const auto empty = run_arwb(options + " --merge " + d.str("nowhere"));
  EXPECT_NE(empty.err.find("--merge " + d.str("nowhere") + ": no cells.jsonl there"), std::string::npos) << empty.err;
}

TEST(LabShards, BadPartsAreOneLine) {
  const std::pair<const char*, const char*> bad[] = {
      {"--shard 4/3 --out /tmp", "--shard '4/3': K is from 1 to N (3)"},
      {"--shard 0/3 --out /tmp", "--shard '0/3': K is from 1 to N (3)"},
      {"--shard two --out /tmp", "--shard 'two' is not K/N, the K-th of N parts (for example 2/4)"},
      {"--shard 1/2", "--shard needs --out: a part's cells are saved there for --merge"},
      {"--shard 1/2 --out /tmp --json", "--shard excludes --json"},
      {"--shard 1/2 --merge /tmp", "--shard excludes --merge"},
  };
  for (const auto& [args, message] : bad) {
    const auto r = run_arwb(std::string("lab --frames-per-cell 1 ") + args);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << "\n" << r.err;
  }
}

}  // namespace
}  // namespace arwb
