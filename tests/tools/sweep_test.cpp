// `trm sweep`: the outputs, the base point against a direct comparison of the two decoders, error falling as a
// precision knob grows, rejected values reported, and bad knob names failing without output.
#include "csv_reader.hpp"
#include "pipeline.hpp"
#include "sweep.hpp"
#include "trm_process.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using trm::test::read_csv;
using trm::test::run_trm;
using trm::test::ScratchDir;

trm::cli::SweepOptions small_sweep(const std::string& knob, int width, int height, int frames) {
  trm::cli::SweepOptions o;
  o.pipeline.scene = "discs";
  o.pipeline.width = width;
  o.pipeline.height = height;
  o.pipeline.frames = frames;
  o.knobs = {knob};
  o.repeats = 1;
  o.hw_size = cv::Size(width, height);
  return o;
}

}  // namespace

TEST(Sweep, QuickWritesEveryFileWithOneRowPerKnobAndValue) {
  ScratchDir tmp("trm-sweep-");
  const auto r = run_trm("sweep --quick --size 24x16 --hw-size 24x16 -o " + tmp.str("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path out = tmp.path() / "out";
  for (const char* name : {"sweep.csv", "sweep.md", "report.json"}) EXPECT_TRUE(fs::exists(out / name)) << name;

  // Every knob the OLED panel uses: its default range (the base value among it), one plot each.
  std::size_t expected_rows = 0;
  std::map<std::string, std::size_t> values_of;
  for (const auto& knob : trm::cli::sweep_knobs()) {
    const fs::path plot = out / ("sweep_" + knob.name + ".png");
    if (!knob.oled || knob.linear_space_only) {  // this sweep is OLED in the encoded resample space
      EXPECT_FALSE(fs::exists(plot)) << knob.name;
      continue;
    }
    const cv::Mat image = cv::imread(plot.string());
    EXPECT_FALSE(image.empty()) << plot;
    EXPECT_EQ(image.cols, 1620) << plot;
    EXPECT_EQ(image.rows, 500) << plot;
    values_of[knob.name] = knob.values.size();
    expected_rows += knob.values.size();
  }
  std::vector<std::string> header;
  const auto rows = read_csv(out / "sweep.csv", &header);
  EXPECT_EQ(rows.size(), expected_rows);
  for (const char* column : {"knob", "value", "is_default", "status", "message", "identical_percent", "max_lsb",
                             "mean_lsb", "rms_lsb", "linear_max", "linear_rms", "seconds_per_frame",
                             "reference_seconds_per_frame", "on_chip_bits", "off_chip_bits", "delta_on_chip_bits",
                             "delta_off_chip_bits", "meets_criterion"}) {
    EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
  }
  // One base row per knob, all the same configuration: the same error and memory, no change of memory.
  std::map<std::string, std::size_t> rows_of, bases_of;
  std::string base_identical;
  for (const auto& row : rows) {
    ++rows_of[row.at("knob")];
    if (row.at("is_default") != "1") continue;
    ++bases_of[row.at("knob")];
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_EQ(row.at("delta_on_chip_bits"), "0");
    EXPECT_EQ(row.at("delta_off_chip_bits"), "0");
    if (base_identical.empty()) base_identical = row.at("identical_percent");
    EXPECT_EQ(row.at("identical_percent"), base_identical) << row.at("knob");
  }
  for (const auto& [knob, n] : values_of) {
    EXPECT_EQ(rows_of[knob], n) << knob;
    EXPECT_EQ(bases_of[knob], 1u) << knob;
  }
  std::ifstream md(out / "sweep.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("| **30** (base) |"), std::string::npos);  // residual_bits, the base value marked
  EXPECT_NE(text.find("trm sweep"), std::string::npos);
  std::ifstream js(out / "report.json");
  const auto report = nlohmann::json::parse(js);
  EXPECT_EQ(report["parameters"]["size"][0], 24);
  EXPECT_EQ(report["knobs"].back()["name"], "lcd_segments_per_octave");
  EXPECT_TRUE(report["knobs"].back().contains("skipped"));
  EXPECT_NE(r.output.find("residual_bits"), std::string::npos);  // the summary table
}

TEST(Sweep, BasePointAgreesWithADirectComparison) {
  // A narrow residual store as the base, so that the comparison is not all-identical (at the default formats every
  // code of this sequence is).
  trm::cli::SweepOptions o = small_sweep("residual_bits", 48, 40, 4);
  o.pipeline.residual_bits = 12;
  o.values = {12};
  const trm::cli::SweepResult result = trm::cli::run_sweep(o);

  // `trm run`'s way: the streaming decoder with the reference beside it, codes compared view by view.
  trm::cli::PipelineOptions direct = o.pipeline;
  direct.impl = "fixed";
  direct.compare_reference = true;
  std::int64_t codes = 0, differing = 0;
  double max_lsb = 0;
  trm::cli::run_pipeline(direct, [&](const trm::cli::DecodedView& view) {
    cv::Mat difference;
    cv::absdiff(view.decoded->drive_codes, view.reference->drive_codes, difference);
    const cv::Mat flat = difference.reshape(1);
    codes += static_cast<std::int64_t>(flat.total());
    differing += cv::countNonZero(flat);
    max_lsb = std::max(max_lsb, cv::norm(flat, cv::NORM_INF));
  });
  ASSERT_EQ(result.knobs.size(), 1u);
  ASSERT_EQ(result.knobs[0].points.size(), 1u);
  const trm::cli::SweepPoint& base = result.knobs[0].points[0];
  EXPECT_TRUE(base.is_default);
  EXPECT_EQ(base.codes, codes);
  EXPECT_EQ(base.differing, differing);
  EXPECT_GT(differing, 0);  // the comparison is not trivially all-identical
  EXPECT_EQ(base.max_lsb, max_lsb);
  EXPECT_DOUBLE_EQ(base.identical_percent, 100.0 * static_cast<double>(codes - differing) / static_cast<double>(codes));
  EXPECT_EQ(result.views, 4);
}

TEST(Sweep, ResidualErrorFallsAsTheStoreWidens) {
  // discs clips (beta outside [0, 1]), so the residual carries the difference the store width decides.
  const trm::cli::SweepResult result = trm::cli::run_sweep(small_sweep("residual_bits", 48, 40, 4));
  const auto& points = result.knobs.at(0).points;
  ASSERT_GE(points.size(), 6u);
  for (std::size_t i = 1; i < points.size(); ++i) {
    ASSERT_TRUE(points[i].ok()) << points[i].message;
    EXPECT_LE(points[i].differing, points[i - 1].differing) << points[i].value;
    EXPECT_LE(points[i].max_lsb, points[i - 1].max_lsb) << points[i].value;
    EXPECT_LE(points[i].rms_lsb, points[i - 1].rms_lsb) << points[i].value;
    EXPECT_GT(points[i].off_chip_bits, points[i - 1].off_chip_bits) << points[i].value;
  }
  EXPECT_GT(points.front().max_lsb, 4.0);  // the narrowest store is visibly worse
  EXPECT_LE(points.back().max_lsb, 1.0);
  EXPECT_TRUE(points.back().meets_criterion());
}

TEST(Sweep, RejectedValuesAreReportedNotFatal) {
  ScratchDir tmp("trm-sweep-");
  // uQ1.16 linear light cannot tell drive codes 0, 1 and 2 apart (rejected by the configuration check).
  const auto r = run_trm("sweep --quick --size 16x12 --knob linear_frac_bits --values 14,16,20 -o " + tmp.str("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::vector<std::string> header;
  const auto rows = read_csv(tmp.path() / "out" / "sweep.csv", &header);
  ASSERT_EQ(rows.size(), 4u);  // 14, 16, 20 and the base 28
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(rows[i].at("status"), "rejected");
    EXPECT_NE(rows[i].at("message").find("drive (linear light)"), std::string::npos) << rows[i].at("message");
    EXPECT_EQ(rows[i].at("meets_criterion"), "0");
  }
  EXPECT_EQ(rows[2].at("status"), "ok");
  EXPECT_EQ(rows[3].at("value"), "28");
  EXPECT_EQ(rows[3].at("is_default"), "1");
  EXPECT_TRUE(fs::exists(tmp.path() / "out" / "sweep_linear_frac_bits.png"));

  // A value the knob itself refuses (the residual store needs a sign and an integer bit), beside one it takes.
  const auto narrow = trm::cli::run_sweep([] {
    auto o = small_sweep("residual_bits", 16, 12, 2);
    o.values = {2, 24};
    return o;
  }());
  ASSERT_EQ(narrow.knobs.at(0).points.size(), 3u);
  EXPECT_EQ(narrow.knobs[0].points[0].status, "rejected");
  EXPECT_NE(narrow.knobs[0].points[0].message.find("out of range"), std::string::npos);
  EXPECT_EQ(narrow.knobs[0].points[1].status, "ok");
}

TEST(Sweep, EveryAskedValueRejectedIsAnError) {
  ScratchDir tmp("trm-sweep-");
  const auto r = run_trm("sweep --quick --size 16x12 --knob linear_frac_bits --values 14,16 -o " + tmp.str("out"));
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("trm: error: --values: every value asked for linear_frac_bits was rejected"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));
}

TEST(Sweep, BadKnobsFailClearlyWithoutOutput) {
  ScratchDir tmp("trm-sweep-");
  const auto r = run_trm("sweep --quick --knob residual_bits --knob no_such_knob -o " + tmp.str("out"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("unknown knob 'no_such_knob'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("residual_bits, "), std::string::npos) << r.output;  // the knobs there are
  EXPECT_EQ(r.output.find("terminate called"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));
  for (const auto& entry : fs::directory_iterator(tmp.path())) {
    EXPECT_EQ(entry.path().filename().string().find(".partial-"), std::string::npos) << entry.path();
  }

  // The other option errors, each with its own message, before anything is decoded.
  struct Case {
    std::function<void(trm::cli::SweepOptions&)> change;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](auto& o) { o.knobs = {"residual_bits", "exp_entries"}, o.values = {8, 9}; }, "exactly one --knob"},
      {[](auto& o) { o.knobs.clear(), o.values = {8}; }, "exactly one --knob"},
      {[](auto& o) { o.repeats = 0; }, "--repeats"},
      {[](auto& o) { o.pipeline.scene = "nosuchscene"; }, "nosuchscene"},
  };
  for (const Case& c : cases) {
    trm::cli::SweepOptions o = small_sweep("residual_bits", 16, 12, 2);
    c.change(o);
    try {
      (void)trm::cli::run_sweep(o);
      ADD_FAILURE() << "accepted; expected: " << c.message;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
    }
  }
}

namespace {

// The fixed-point decoders resample in linear light too: its knobs sweep there, and say why they skip elsewhere.
TEST(Sweep, LinearResampleSpaceKnobsSweepInLinearSpaceOnly) {
  auto linear = small_sweep("linear_resample_frac_bits", 16, 12, 2);
  linear.pipeline.encoder.resample_space = trm::ResampleSpace::Linear;
  linear.values = {16, 24};
  const auto swept = trm::cli::run_sweep(linear);
  ASSERT_EQ(swept.knobs.size(), 1u);
  EXPECT_TRUE(swept.knobs[0].skipped.empty());
  ASSERT_EQ(swept.knobs[0].points.size(), 3u);  // 16, 24 and the base 32
  EXPECT_EQ(swept.knobs[0].points[2].value, 32);
  EXPECT_TRUE(swept.knobs[0].points[2].is_default);
  EXPECT_TRUE(swept.knobs[0].points[1].ok());

  auto encoded = small_sweep("linear_resample_frac_bits", 16, 12, 2);
  const auto skipped = trm::cli::run_sweep(encoded);
  ASSERT_EQ(skipped.knobs.size(), 1u);
  EXPECT_NE(skipped.knobs[0].skipped.find("--resample-space linear"), std::string::npos) << skipped.knobs[0].skipped;
}

}  // namespace
