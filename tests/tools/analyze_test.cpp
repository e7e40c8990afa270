// `trm analyze`: the quick run's CSV shape and trends, the analysis-only 1 + k cycle model against the real encoder and
// decoder at k = 1, and bad input refused with one message and no output directory.
#include "trm_process.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using trm::test::run_trm;

class AnalyzeTempDir : public trm::test::ScratchDir {
 public:
  AnalyzeTempDir() : ScratchDir("trm-analyze-") {}
};

// A CSV file as a header and rows of named cells.
struct Csv {
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
};

std::vector<std::string> split(const std::string& line, char by) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  for (std::string cell; std::getline(in, cell, by);) cells.push_back(cell);
  if (!line.empty() && line.back() == by) cells.emplace_back();
  return cells;
}

Csv read_csv(const fs::path& path) {
  Csv csv;
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line)) return csv;
  csv.header = split(line, ',');
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = split(line, ',');
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < csv.header.size() && i < cells.size(); ++i) row[csv.header[i]] = cells[i];
    if (cells.size() != csv.header.size()) row["__bad"] = line;
    csv.rows.push_back(row);
  }
  return csv;
}

double number(const std::map<std::string, std::string>& row, const std::string& key) { return std::stod(row.at(key)); }

// The quick grid: 1 speed (10 deg/s), 2 values of each parameter, r in {1, 0.7, 0.5, 0.3, 0.1}; discs at 100 and
// 165 Hz; cycles 1 + 1 and 1 + 2.
TEST(Analyze, QuickRunWritesEveryTableAndTheEnergyRisesWithPixelsSaved) {
  AnalyzeTempDir tmp;
  const auto run = run_trm("analyze --quick --out " + tmp.str("a"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const char* name : {"analyze.md", "study.csv", "experiment1.csv", "cycles.csv", "study_contrast.png",
                           "study_ppd.png", "study_refresh.png", "experiment1.png", "cycles.png"}) {
    EXPECT_TRUE(fs::exists(tmp.path() / "a" / name)) << name;
  }

  const Csv study = read_csv(tmp.path() / "a" / "study.csv");
  EXPECT_EQ(study.header, (std::vector<std::string>{"parameter", "value", "speed_deg_s", "reduction",
                                                    "pixels_saved_percent", "energy"}));
  ASSERT_EQ(study.rows.size(), 3u * 2u * 1u * 5u);
  std::map<std::pair<std::string, std::string>, std::map<double, double>> curves;  // (parameter, value) -> r -> E
  for (const auto& row : study.rows) {
    ASSERT_EQ(row.count("__bad"), 0u) << row.at("__bad");
    const double r = number(row, "reduction");
    EXPECT_NEAR(number(row, "pixels_saved_percent"), 100.0 * (0.5 - 0.5 * r * r), 1e-7);
    EXPECT_GE(number(row, "energy"), 0.0);
    curves[{row.at("parameter"), row.at("value")}][r] = number(row, "energy");
  }
  ASSERT_EQ(curves.size(), 6u);
  for (const auto& [key, curve] : curves) {
    // At a fixed speed, reducing the odd frames further (more pixels saved) makes TRM more visible: the energy rises
    // from r = 1 (nothing saved, only D's blur) through 0.7, 0.5 to 0.3 (45.5 % saved). r = 0.1 is not held to it:
    // there the energy of some curves falls again (docs/analyze.md).
    EXPECT_GT(curve.at(0.7), curve.at(1.0)) << key.first << " " << key.second;
    EXPECT_GT(curve.at(0.5), curve.at(0.7)) << key.first << " " << key.second;
    EXPECT_GT(curve.at(0.3), curve.at(0.5)) << key.first << " " << key.second;
  }
  // A lower contrast of the same square gives a smaller difference everywhere but r = 1.
  for (double r : {0.1, 0.3, 0.5}) {
    EXPECT_LT(curves.at({"contrast", "0.1"}).at(r), curves.at({"contrast", "0.4"}).at(r)) << r;
  }

  const Csv exp1 = read_csv(tmp.path() / "a" / "experiment1.csv");
  ASSERT_EQ(exp1.rows.size(), 2u);
  for (const auto& row : exp1.rows) {
    EXPECT_EQ(row.at("scene"), "discs");
    const double r = number(row, "threshold_reduction");
    EXPECT_GT(r, 0.0);
    EXPECT_LE(r, 1.0);
  }
  // The threshold is the energy of discs at 100 Hz and r = 0.4, so that condition's threshold r is 0.4 to within the
  // bisection's step of the grid's 0.2-wide bracket (0.2 / 2^4).
  EXPECT_NEAR(number(exp1.rows[0], "threshold_reduction"), 0.4, 0.2 / 16 + 1e-9);

  const Csv cycles = read_csv(tmp.path() / "a" / "cycles.csv");
  ASSERT_EQ(cycles.rows.size(), 2u * 5u);
  for (const auto& row : cycles.rows) {
    const int k = std::stoi(row.at("reduced_frames"));
    const double r = number(row, "reduction");
    EXPECT_NEAR(number(row, "pixels_saved_percent"), 100.0 * k / (k + 1.0) * (1.0 - r * r), 1e-7);
    EXPECT_NEAR(number(row, "cycle_hz"), 90.0 / (k + 1), 1e-9);
    if (k == 1) {
      // The analysis-only cycle model is the reference decoder's rule at k = 1: the real encoder and decoder give
      // the same energy on this OLED-type panel.
      EXPECT_NEAR(number(row, "energy"), number(row, "pipeline_energy"), 1e-6 * number(row, "pipeline_energy") + 1e-9)
          << "r " << r;
    } else {
      EXPECT_TRUE(row.at("pipeline_energy").empty());
    }
  }
}

TEST(Analyze, BadInputGivesOneMessageAndNoOutput) {
  AnalyzeTempDir tmp;
  const std::vector<std::pair<std::string, std::string>> cases{
      {"--ppd 0", "--ppd"},
      {"--ppds 30,-1", "--ppds"},
      {"--speeds 5,nan", "--speeds"},
      {"--refresh 0", "--refresh"},
      {"--refreshes 90,-5", "--refreshes"},
      {"--exp1-ppd 0", "--exp1-ppd"},
      {"--scenes discs,nosuch", "unknown scene 'nosuch'"},
      {"--contrast 1.5", "--contrast"},
      {"--cycles 0", "--cycles"},
  };
  for (const auto& [args, expected] : cases) {
    const auto run = run_trm("analyze --quick " + args + " --out " + tmp.str("bad"));
    EXPECT_NE(run.exit_code, 0) << args;
    EXPECT_NE(run.output.find("trm: error:"), std::string::npos) << args << ": " << run.output;
    EXPECT_NE(run.output.find(expected), std::string::npos) << args << ": " << run.output;
    EXPECT_FALSE(fs::exists(tmp.path() / "bad")) << args;
    EXPECT_EQ(run.output.find("trm: error:"), run.output.rfind("trm: error:")) << args << ": " << run.output;
  }
}

}  // namespace
