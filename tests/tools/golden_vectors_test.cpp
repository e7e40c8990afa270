// The checked-in golden vectors (tests/golden/vectors.txt): every stage file of `trm vectors` for a few small
// scenes, as 64-bit FNV-1a hashes. Any change of the fixed-point decoder's bits must be deliberate.
#include "trm_process.hpp"
#include "vectors.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

using TrmRun = trm::test::TrmResult;
using trm::test::run_trm;

// "<scene> <panel> <file>" -> hash, comment lines skipped.
std::map<std::string, std::string> parse(const std::string& text) {
  std::map<std::string, std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto last = line.rfind(' ');
    out[line.substr(0, last)] = line.substr(last + 1);
  }
  return out;
}

TEST(GoldenVectors, FixedDecoderStagesMatchTheCheckedInHashes) {
  const std::string path = std::string(TRM_SOURCE_DIR) + "/tests/golden/vectors.txt";
  std::ifstream file(path);
  ASSERT_TRUE(file) << "missing " << path << "; create it with: trm vectors --update-golden tests/golden/vectors.txt";
  std::stringstream stored;
  stored << file.rdbuf();
  const auto expected = parse(stored.str());
  const auto actual = parse(trm::cli::golden_vectors_text());
  const std::string update = "if the change is deliberate, update with: trm vectors --update-golden tests/golden/vectors.txt";
  int differences = 0;
  for (const auto& [key, hash] : actual) {
    const auto found = expected.find(key);
    if (found == expected.end()) {
      ADD_FAILURE() << "new stage file (scene panel file): " << key;
      ++differences;
    } else if (found->second != hash) {
      ADD_FAILURE() << "changed (scene panel file): " << key << ": expected " << found->second << ", got " << hash;
      ++differences;
    }
  }
  for (const auto& [key, hash] : expected) {
    if (actual.find(key) == actual.end()) {
      ADD_FAILURE() << "stage file no longer produced (scene panel file): " << key;
      ++differences;
    }
  }
  EXPECT_EQ(differences, 0) << update;
  EXPECT_GT(actual.size(), 100u);
}

TEST(HwReport, WritesJsonWithTotalsAndThePaperComparison) {
  const trm::test::ScratchDir scratch("trm-hw-");
  const fs::path& dir = scratch.path();
  const TrmRun r = run_trm("hw-report --size 64x48 --panel lcd --residual-bits 18 --json " + (dir / "hw.json").string() +
                    " --out " + (dir / "out").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("paper's previous frame + residual"), std::string::npos) << r.output;
  std::ifstream in(dir / "hw.json");
  const auto report = nlohmann::json::parse(in);
  const auto& hw = report["hardware"];
  // --residual-bits 18 is sQ2.16, as the one decoder-configuration writer records it.
  const auto& residual = report["parameters"]["decoder"]["residual"];
  EXPECT_EQ(residual["int_bits"], 2);
  EXPECT_EQ(residual["frac_bits"], 16);
  EXPECT_EQ(residual["signed"], true);
  EXPECT_EQ(report["parameters"]["decoder"]["decoder"]["panel"]["kind"], "lcd");
  const auto& totals = hw["totals"];
  EXPECT_EQ(totals["on_chip_bits"].get<std::int64_t>(),
            totals["line_buffer_bits"].get<std::int64_t>() + totals["rom_bits"].get<std::int64_t>());
  EXPECT_GT(hw["paper_comparison"]["saved_bits"].get<std::int64_t>(), 0);
  EXPECT_FALSE(hw["roms"].empty());
  EXPECT_FALSE(hw["arithmetic"].empty());
  EXPECT_TRUE(fs::exists(dir / "out" / "report.json"));
}

TEST(HwReport, BadInputFailsWithoutOutput) {
  const trm::test::ScratchDir scratch("trm-hw-");
  const fs::path& dir = scratch.path();
  for (const std::string& args : {std::string("hw-report --residual-bits 2"), std::string("hw-report --residual-bits 40"),
                                  std::string("hw-report --size 0x4"), std::string("vectors --scene nope"),
                                  std::string("vectors --scene discs --size 3"),
                                  std::string("vectors --scene discs --frames 0")}) {
    const TrmRun r = run_trm(args + " --out " + (dir / "out").string());
    EXPECT_NE(r.exit_code, 0) << args << "\n" << r.output;
    EXPECT_FALSE(r.output.empty()) << args;
    EXPECT_FALSE(fs::exists(dir / "out")) << args;
  }
}

TEST(Vectors, WritesOneHexFilePerStageAndAReadme) {
  const trm::test::ScratchDir scratch("trm-hw-");
  const fs::path& dir = scratch.path();
  const TrmRun r = run_trm("vectors --scene checker --frames 2 --size 10x6 --panel lcd --out " + (dir / "v").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream readme(dir / "v" / "README.md");
  std::stringstream text;
  text << readme.rdbuf();
  EXPECT_NE(text.str().find("sQ3.28"), std::string::npos);  // beta, from the configuration
  std::ifstream beta(dir / "v" / "frame_000_full_beta.hex");
  std::string line;
  int lines = 0;
  while (std::getline(beta, line)) {
    ++lines;
    EXPECT_EQ(line.size(), 10u * 3u * 9u - 1u);  // 30 words of 8 hex digits (31 bits), one space between
  }
  EXPECT_EQ(lines, 6);
  EXPECT_TRUE(fs::exists(dir / "v" / "frame_001_reduced_w.hex"));
}

}  // namespace
