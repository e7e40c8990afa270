// `trm bench --quick`: the JSON names every contender at every size and panel, and every figure is finite and
// positive. No timing threshold: speed is the benchmark's figure, never a test's verdict.
#include "trm_process.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <set>
#include <string>

namespace {

using trm::test::run_trm;
using trm::test::ScratchDir;

void expect_positive(const nlohmann::json& value, const std::string& what) {
  ASSERT_TRUE(value.is_number()) << what;
  const double v = value.get<double>();
  EXPECT_TRUE(std::isfinite(v) && v > 0.0) << what << " = " << v;
}

TEST(Bench, QuickWritesEveryContenderWithFinitePositiveFigures) {
  ScratchDir dir("trm_bench_");
  const std::string json_path = dir.str("bench.json");
  const auto result = run_trm("bench --quick --threads 2 --json " + json_path);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("opencv-float32"), std::string::npos) << result.output;
  std::ifstream in(json_path);
  const nlohmann::json report = nlohmann::json::parse(in);
  expect_positive(report["machine"]["hardware_threads"], "hardware_threads");
  EXPECT_EQ(report["parameters"]["skip_unneeded"], true);
  const nlohmann::json& results = report["results"];
  ASSERT_TRUE(results.is_array());
  ASSERT_EQ(results.size(), 4u);  // two sizes x (OLED, LCD)
  std::set<std::string> panels;
  for (const nlohmann::json& r : results) {
    panels.insert(r["panel"].get<std::string>());
    expect_positive(r["size"][0], "width");
    expect_positive(r["size"][1], "height");
    expect_positive(r["link_frames"], "link_frames");
    expect_positive(r["output_mpix_per_frame"], "output_mpix_per_frame");
    for (const char* field : {"on_chip_mib", "off_chip_mib", "output_frame_mib", "total_mib"}) {
      expect_positive(r["hw_report_memory"][field], field);
    }
    std::set<std::string> names;
    for (const nlohmann::json& d : r["decoders"]) {
      const std::string name = d["name"].get<std::string>();
      names.insert(name);
      for (const char* field : {"threads", "mpix_per_s", "ms_per_frame", "ratio_to_opencv", "peak_rss_mib",
                                "rss_before_mib", "first_pair_ms"}) {
        expect_positive(d[field], name + " " + field);
      }
      // The working memory is the peak less the resident set before: within [0, peak], and its ratio to the
      // resource report's memory is that quotient.
      ASSERT_TRUE(d["working_mib"].is_number()) << name;
      const double working = d["working_mib"].get<double>();
      EXPECT_GE(working, 0.0) << name;
      EXPECT_LE(working, d["peak_rss_mib"].get<double>()) << name;
      EXPECT_DOUBLE_EQ(d["working_over_hw_report"].get<double>(),
                       working / r["hw_report_memory"]["total_mib"].get<double>()) << name;
      for (const char* hz : {"90", "120", "144"}) expect_positive(d["realtime_factor"][hz], name + " RT " + hz);
      ASSERT_EQ(d["repeat_seconds"].size(), 2u) << name;
      for (const nlohmann::json& s : d["repeat_seconds"]) expect_positive(s, name + " repeat");
      ASSERT_EQ(d["repeat_first_pair_seconds"].size(), 2u) << name;
      for (const nlohmann::json& s : d["repeat_first_pair_seconds"]) expect_positive(s, name + " first pair");
      // The drive codes alone skip the report-only motion tests; the decoders with report planes keep them.
      if (name == "fixed" || name == "fixed-1t") {
        EXPECT_EQ(d["motion_weight_statistics"], false) << name;
      } else if (name == "fixed+planes" || name == "fixed-frame") {
        EXPECT_EQ(d["motion_weight_statistics"], true) << name;
      } else {
        EXPECT_TRUE(d["motion_weight_statistics"].is_null()) << name;
      }
    }
    EXPECT_EQ(names, (std::set<std::string>{"fixed", "fixed-1t", "fixed+planes", "fixed-frame", "reference",
                                              "reference+planes", "opencv-float32"}));
    // DESIGN §6 on the bench's own views: the verdict is the criterion applied to the figures beside it, and at the
    // default formats it is met.
    const nlohmann::json& agreement = r["reference_agreement"];
    expect_positive(agreement["codes"], "agreement codes");
    const double identical = agreement["identical_percent"].get<double>();
    EXPECT_GE(identical, 0.0);
    EXPECT_LE(identical, 100.0);
    const double max_lsb = agreement["max_lsb"].get<double>();
    EXPECT_EQ(agreement["meets_design_6"].get<bool>(), identical >= 99.9 && max_lsb <= 1.0) << agreement.dump();
    EXPECT_TRUE(agreement["meets_design_6"].get<bool>()) << r["panel"] << " " << agreement.dump();
    EXPECT_EQ(agreement["lcd_synchronised"].get<bool>(), r["panel"] == "lcd");
  }
  EXPECT_EQ(panels, (std::set<std::string>{"vive", "lcd"}));
  EXPECT_TRUE(report["parameters"]["formats"].empty());
}

// On one thread the banded decoder is the one-thread decoder: timed once, as "fixed", whichever of the two names
// --only asks for (asking for fixed-1t timed nothing but the yardstick before).
TEST(Bench, OneThreadTimesTheOneThreadDecoderUnderEitherName) {
  ScratchDir dir("trm_bench_one_thread_");
  for (const std::string name : {"fixed", "fixed-1t"}) {
    const std::string json_path = dir.str(name + ".json");
    const auto result = run_trm("bench --quick --size 128x96 --panel vive --threads 1 --only " + name + " --json " + json_path);
    ASSERT_EQ(result.exit_code, 0) << result.output;
    std::ifstream in(json_path);
    const nlohmann::json report = nlohmann::json::parse(in);
    ASSERT_EQ(report["results"].size(), 1u);
    std::set<std::string> names;
    for (const nlohmann::json& d : report["results"][0]["decoders"]) {
      names.insert(d["name"].get<std::string>());
      if (d["name"] == "fixed") {
        EXPECT_EQ(d["threads"], 1) << name;
      }
    }
    EXPECT_EQ(names, (std::set<std::string>{"fixed", "opencv-float32"})) << name;
  }
}

// --format sets the fixed-point decoders' formats by trm sweep's knobs and is recorded; the §6 check then judges
// those formats: linear light uQ1.16 cannot tell the darkest drive codes apart and is rejected before any work,
// and a set that is accepted is held to the reference like the defaults.
TEST(Bench, FormatSetsAreAppliedCheckedAndRecorded) {
  ScratchDir dir("trm_bench_format_");
  const std::string json_path = dir.str("bench.json");
  const auto narrow = run_trm("bench --quick --size 128x96 --panel vive --only fixed --format linear_frac_bits=18 "
                              "--format bilinear_weight_frac_bits=8 --json " + json_path);
  ASSERT_EQ(narrow.exit_code, 0) << narrow.output;
  EXPECT_NE(narrow.output.find("linear_frac_bits=18 bilinear_weight_frac_bits=8"), std::string::npos) << narrow.output;
  std::ifstream in(json_path);
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["parameters"]["formats"],
            nlohmann::json::array({"linear_frac_bits=18", "bilinear_weight_frac_bits=8"}));
  ASSERT_EQ(report["results"].size(), 1u);
  expect_positive(report["results"][0]["reference_agreement"]["codes"], "agreement codes");

  const std::string rejected_path = dir.str("rejected.json");
  for (const std::string bad : {"linear_frac_bits=16", "no_such_knob=3", "linear_frac_bits", "residual_bits=x",
                                 "eye_substeps=2", "linear_resample_frac_bits=24"}) {
    const auto result = run_trm("bench --quick --format " + bad + " --json " + rejected_path);
    EXPECT_NE(result.exit_code, 0) << bad;
    EXPECT_NE(result.output.find("--format"), std::string::npos) << bad << ": " << result.output;
    EXPECT_EQ(result.output.find("Mpix/s"), std::string::npos) << bad << ": rejected before any work";
    EXPECT_FALSE(std::ifstream(rejected_path).good()) << bad;
  }
}

// --no-skip times the fixed-point decoders with every step run (the rate no content goes below), says so and records
// it; their codes are still the reference's by DESIGN §6.
TEST(Bench, NoSkipRunsEveryStepAndSaysSo) {
  ScratchDir dir("trm_bench_no_skip_");
  const std::string json_path = dir.str("bench.json");
  const auto result = run_trm("bench --quick --size 128x96 --panel vive --only fixed --no-skip --json " + json_path);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("no skips"), std::string::npos) << result.output;
  std::ifstream in(json_path);
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["parameters"]["skip_unneeded"], false);
  ASSERT_EQ(report["results"].size(), 1u);
  expect_positive(report["results"][0]["reference_agreement"]["codes"], "agreement codes");
  EXPECT_EQ(report["results"][0]["reference_agreement"]["meets_design_6"], true) << result.output;
}

}  // namespace
