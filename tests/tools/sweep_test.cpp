// `trm sweep`: the outputs, the base point against a direct comparison of the two decoders, error falling as a
// precision knob grows, rejected values reported, bad knob names failing without output, the linear-resample-space
// knobs around their own base, the eye model's sub-steps converging, the perceived error and the Pareto front.
#include "csv_reader.hpp"
#include "pipeline.hpp"
#include "sweep.hpp"
#include "sweep_report.hpp"
#include "trm/media.hpp"
#include "trm_process.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
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

  // Every knob the OLED panel uses, the linear-resample-space and eye-model ones too: its default range (the base
  // value among it), one plot each.
  std::size_t expected_rows = 0;
  std::map<std::string, std::size_t> values_of;
  for (const auto& knob : trm::cli::sweep_knobs()) {
    const fs::path plot = out / ("sweep_" + knob.name + ".png");
    if (!knob.oled) {  // this sweep is OLED
      EXPECT_FALSE(fs::exists(plot)) << knob.name;
      continue;
    }
    const cv::Mat image = trm::media::read_image(plot.string(), cv::IMREAD_COLOR);
    EXPECT_FALSE(image.empty()) << plot;
    EXPECT_EQ(image.cols, 1620) << plot;
    EXPECT_EQ(image.rows, 500) << plot;
    values_of[knob.name] = knob.values.size();
    expected_rows += knob.values.size();
  }
  const cv::Mat pareto = trm::media::read_image((out / "sweep_pareto.png").string(), cv::IMREAD_COLOR);
  EXPECT_EQ(pareto.cols, 1800);
  EXPECT_EQ(pareto.rows, 560);
  std::vector<std::string> header;
  const auto rows = read_csv(out / "sweep.csv", &header);
  EXPECT_EQ(rows.size(), expected_rows);
  for (const char* column : {"knob", "resample_space", "value", "is_default", "status", "message",
                             "identical_percent", "max_lsb", "mean_lsb", "rms_lsb", "linear_max", "linear_rms",
                             "perceived_psnr_db", "visual_difference", "seconds_per_frame",
                             "reference_seconds_per_frame", "eye_seconds_per_frame", "on_chip_bits", "off_chip_bits",
                             "delta_on_chip_bits", "delta_off_chip_bits", "meets_criterion"}) {
    EXPECT_NE(std::find(header.begin(), header.end(), column), header.end()) << column;
  }
  // One base row per knob, all the same configuration in each resample space: the same error and memory, no
  // change of memory; every point's perceived figures and eye-model time are there.
  std::map<std::string, std::size_t> rows_of, bases_of;
  std::map<std::string, std::string> base_identical, base_on_chip;
  for (const auto& row : rows) {
    ++rows_of[row.at("knob")];
    if (row.at("status") == "ok") {
      EXPECT_FALSE(row.at("perceived_psnr_db").empty()) << row.at("knob");
      EXPECT_GT(std::stod(row.at("eye_seconds_per_frame")), 0.0) << row.at("knob");
    }
    if (row.at("is_default") != "1") continue;
    ++bases_of[row.at("knob")];
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_EQ(row.at("delta_on_chip_bits"), "0");
    EXPECT_EQ(row.at("delta_off_chip_bits"), "0");
    const std::string space = row.at("resample_space");
    if (base_identical[space].empty()) base_identical[space] = row.at("identical_percent");
    if (base_on_chip[space].empty()) base_on_chip[space] = row.at("on_chip_bits");
    EXPECT_EQ(row.at("identical_percent"), base_identical[space]) << row.at("knob");
    EXPECT_EQ(row.at("on_chip_bits"), base_on_chip[space]) << row.at("knob");
  }
  EXPECT_EQ(base_identical.size(), 2u);  // encoded, and the linear-resample-space knobs' own base
  EXPECT_NE(base_on_chip["encoded"], base_on_chip["linear"]);
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
  const auto& knobs = report["knobs"];
  const auto lcd = std::find_if(knobs.begin(), knobs.end(),
                                [](const auto& k) { return k["name"] == "lcd_segments_per_octave"; });
  ASSERT_NE(lcd, knobs.end());
  EXPECT_TRUE(lcd->contains("skipped"));
  EXPECT_EQ(knobs.back()["name"], "eye_substeps");
  EXPECT_TRUE(knobs.back()["eye_model"].get<bool>());
  ASSERT_EQ(report["pareto"].size(), 3u);
  for (const auto& front : report["pareto"]) EXPECT_FALSE(front["front"].empty()) << front["chart"];
  EXPECT_TRUE(report.contains("linear_base"));
  EXPECT_NE(text.find("## Pareto front"), std::string::npos);
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

// The linear-resample-space knobs used to be skipped in an encoded-space run (the decoder does not use them there):
// they sweep around a base of their own, the same options in linear space, which is what a run in that space has.
TEST(Sweep, LinearResampleSpaceKnobsSweepAroundALinearBase) {
  auto encoded = small_sweep("linear_resample_frac_bits", 16, 12, 2);
  encoded.values = {16, 24};
  const auto own = trm::cli::run_sweep(encoded);
  auto linear = encoded;
  linear.pipeline.encoder.resample_space = trm::ResampleSpace::Linear;
  const auto direct = trm::cli::run_sweep(linear);
  ASSERT_EQ(own.knobs.size(), 1u);
  ASSERT_EQ(direct.knobs.size(), 1u);
  EXPECT_TRUE(own.knobs[0].skipped.empty()) << own.knobs[0].skipped;
  EXPECT_EQ(own.knobs[0].resample_space, trm::ResampleSpace::Linear);
  ASSERT_TRUE(own.linear_base.has_value());
  EXPECT_FALSE(direct.linear_base.has_value());  // the run's own base is already in linear space
  ASSERT_EQ(own.knobs[0].points.size(), 3u);     // 16, 24 and the base 32
  EXPECT_EQ(own.knobs[0].points[2].value, 32);
  EXPECT_TRUE(own.knobs[0].points[2].is_default);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& a = own.knobs[0].points[i];
    const auto& b = direct.knobs[0].points[i];
    ASSERT_EQ(a.status, b.status) << a.value << ": " << a.message;
    if (!a.ok()) continue;
    EXPECT_EQ(a.codes, b.codes) << a.value;
    EXPECT_EQ(a.differing, b.differing) << a.value;
    EXPECT_EQ(a.max_lsb, b.max_lsb) << a.value;
    EXPECT_EQ(a.on_chip_bits, b.on_chip_bits) << a.value;
    EXPECT_EQ(a.delta_on_chip_bits, b.delta_on_chip_bits) << a.value;
  }
  // The linear-space decoder is another decoder (linear line buffers, no EOTF ROM), and the knob sets its lin(E) ROM.
  EXPECT_NE(own.linear_base->on_chip_bits, own.base.on_chip_bits);
  ASSERT_TRUE(own.knobs[0].points[1].ok()) << own.knobs[0].points[1].message;
  EXPECT_LT(own.knobs[0].points[1].on_chip_bits, own.knobs[0].points[2].on_chip_bits);
}

// Brute force: a point is on the front when no other point has cost <= and error <= with one of them <.
TEST(Sweep, ParetoFrontIsEveryUndominatedPoint) {
  cv::RNG rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 1 + trial % 17;
    std::vector<double> cost(n), error(n);
    for (int i = 0; i < n; ++i) {
      cost[i] = rng.uniform(0, 6);   // few distinct values: ties in cost, in error and whole points
      error[i] = rng.uniform(0, 6);
    }
    std::vector<std::size_t> expected;
    for (int i = 0; i < n; ++i) {
      bool dominated = false;
      for (int j = 0; j < n; ++j) {
        dominated = dominated || (cost[j] <= cost[i] && error[j] <= error[i] &&
                                  (cost[j] < cost[i] || error[j] < error[i]));
      }
      if (!dominated) expected.push_back(static_cast<std::size_t>(i));
    }
    std::vector<std::size_t> front = trm::cli::pareto_front(cost, error);
    for (std::size_t k = 1; k < front.size(); ++k) EXPECT_LE(cost[front[k - 1]], cost[front[k]]);
    std::sort(front.begin(), front.end());
    EXPECT_EQ(front, expected) << "trial " << trial;
  }
  EXPECT_THROW((void)trm::cli::pareto_front({1.0}, {}), std::invalid_argument);
}

// The eye model's sub-steps: the base decoder watched at S against the reference decoder at the exact eye. The exact
// eye itself leaves nothing (a value the reference is made with), the error falls as S grows, values that do not
// divide the exact eye's sub-steps are rejected, and the decoder's own figures stay the base's.
TEST(Sweep, EyeSubstepsConvergeToTheExactEye) {
  // Wide enough that the fastest disc travels pixels per frame (speeds are fractions of the view size): at 48x40 the
  // eye's travel within a lit OLED window stays inside one pixel interval, where every sub-step count is exact.
  auto o = small_sweep("eye_substeps", 240, 32, 4);
  o.values = {1, 3, 4, 32, trm::cli::kExactEyeSubsteps};
  const auto result = trm::cli::run_sweep(o);
  ASSERT_EQ(result.knobs.size(), 1u);
  const auto& points = result.knobs[0].points;
  ASSERT_EQ(points.size(), 6u);  // 1, 3, 4, 16 (base), 32, 256
  EXPECT_EQ(points[1].status, "rejected");
  EXPECT_NE(points[1].message.find("does not divide"), std::string::npos) << points[1].message;
  EXPECT_TRUE(points[3].is_default);
  EXPECT_NE(result.target_velocity_deg_s, 0.0);  // discs move: the eye pursues
  const std::vector<const trm::cli::SweepPoint*> ok = {&points[0], &points[2], &points[3], &points[4]};
  for (std::size_t i = 1; i < ok.size(); ++i) {
    EXPECT_LT(ok[i]->visual_difference, ok[i - 1]->visual_difference) << ok[i]->value;
    EXPECT_GT(ok[i]->perceived_psnr_db, ok[i - 1]->perceived_psnr_db) << ok[i]->value;
  }
  EXPECT_GT(ok.front()->visual_difference, 0.0);
  // At the exact eye's own sub-steps only the base decoder's difference from the reference is left: none here.
  EXPECT_EQ(result.base.differing, 0);
  EXPECT_EQ(points[5].visual_difference, 0.0);
  EXPECT_TRUE(std::isinf(points[5].perceived_psnr_db));
  for (const auto& p : points) {
    if (!p.ok()) continue;
    EXPECT_EQ(p.codes, result.base.codes);
    EXPECT_EQ(p.on_chip_bits, result.base.on_chip_bits);
    EXPECT_EQ(p.delta_off_chip_bits, 0);
    EXPECT_GT(p.eye_seconds_per_frame, 0.0);
  }
}

// A decoder knob's perceived error is its decoder's against the reference's, seen by the same eye: nothing where the
// codes agree, and more as the residual store narrows.
TEST(Sweep, PerceivedErrorFollowsTheDecodersCodes) {
  auto o = small_sweep("residual_bits", 48, 40, 4);
  o.values = {6, 12};
  const auto result = trm::cli::run_sweep(o);
  const auto& points = result.knobs.at(0).points;
  ASSERT_EQ(points.size(), 3u);  // 6, 12, the base 30
  for (const auto& p : points) ASSERT_TRUE(p.ok()) << p.value << ": " << p.message;
  EXPECT_EQ(points[2].differing, 0);
  EXPECT_TRUE(std::isinf(points[2].perceived_psnr_db));
  EXPECT_EQ(points[2].visual_difference, 0.0);
  EXPECT_GT(points[0].differing, points[1].differing);
  EXPECT_LT(points[0].perceived_psnr_db, points[1].perceived_psnr_db);
  EXPECT_TRUE(std::isfinite(points[1].perceived_psnr_db));
  EXPECT_GT(points[0].visual_difference, 0.0);
}

// The LCD's LC model: the base decoder's output through each model against the reference (second order,
// overdriven) at the base eye. The reference value is its own reference; the first-order crystal has no inertia, so
// on moving discs it shows another light than the second-order one; the decoder's figures stay the base's.
TEST(Sweep, LcModelIsHeldToTheSecondOrderOverdrivenCrystal) {
  const trm::cli::SweepKnob* knob = trm::cli::find_sweep_knob("lc_model");
  ASSERT_NE(knob, nullptr);
  EXPECT_TRUE(knob->eye_model);
  EXPECT_FALSE(knob->oled);
  auto o = small_sweep("lc_model", 240, 32, 4);
  o.pipeline.panel = trm::parse_panel("lcd");
  const auto result = trm::cli::run_sweep(o);
  ASSERT_EQ(result.knobs.size(), 1u);
  EXPECT_EQ(result.knobs[0].default_value, 0);  // the plain LCD preset: first order, no overdrive
  const auto& points = result.knobs[0].points;
  ASSERT_EQ(points.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    const auto& p = points[static_cast<std::size_t>(i)];
    ASSERT_TRUE(p.ok()) << i << ": " << p.message;
    EXPECT_EQ(p.value, i);
    EXPECT_EQ(p.is_default, i == 0);
    EXPECT_EQ(p.codes, result.base.codes);
    EXPECT_EQ(p.differing, result.base.differing);
    EXPECT_EQ(p.on_chip_bits, result.base.on_chip_bits);
    EXPECT_GT(p.eye_seconds_per_frame, 0.0);
  }
  EXPECT_EQ(knob->value_label(trm::cli::kLcModelReference), "second+overdrive");
  EXPECT_EQ(points[3].visual_difference, 0.0);
  EXPECT_TRUE(std::isinf(points[3].perceived_psnr_db));
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_GT(points[i].visual_difference, 0.0) << i;
    EXPECT_TRUE(std::isfinite(points[i].perceived_psnr_db)) << i;
  }
  EXPECT_NE(points[0].visual_difference, points[2].visual_difference);
  EXPECT_NE(points[0].perceived_psnr_db, points[2].perceived_psnr_db);

  // The decoder does not depend on the LC model (Eq. 7's drive), so a base that is already the reference shows the
  // same output through the same models: the same figures, exactly, with the base now the exact one.
  auto detailed = o;
  detailed.pipeline.panel.lcd.lc_second_order = trm::LcSecondOrderParams{};
  detailed.pipeline.panel.lcd.overdrive = true;
  detailed.values = {0};
  const auto again = trm::cli::run_sweep(detailed);
  EXPECT_EQ(again.knobs.at(0).default_value, trm::cli::kLcModelReference);
  const auto& twice = again.knobs[0].points;
  ASSERT_EQ(twice.size(), 2u);  // 0, and the base 3
  EXPECT_TRUE(twice[1].is_default);
  EXPECT_EQ(twice[1].visual_difference, 0.0);
  EXPECT_EQ(twice[0].visual_difference, points[0].visual_difference);
  EXPECT_EQ(twice[0].perceived_psnr_db, points[0].perceived_psnr_db);

  trm::cli::SweepConfig config;
  try {
    knob->set(config, 4);
    ADD_FAILURE() << "lc_model 4 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("lc_model 4 is none of the LC models 0..3"), std::string::npos) << e.what();
  }
  // An OLED has no liquid crystal: the knob is skipped with the reason, as the other LCD-only knobs are.
  const auto oled = trm::cli::run_sweep(small_sweep("lc_model", 16, 12, 2));
  ASSERT_EQ(oled.knobs.size(), 1u);
  EXPECT_EQ(oled.knobs[0].skipped, "used with the LCD panel only");
  EXPECT_TRUE(oled.knobs[0].points.empty());
}

// The LC model in the outputs: its values by name in sweep.csv, sweep.md, report.json and the knob list, and a
// Pareto front of its own (its reference is not the exact eye's).
TEST(Sweep, LcModelIsWrittenWithItsValueNames) {
  ScratchDir tmp("trm-sweep-");
  const auto ok = run_trm("sweep --quick --panel lcd --knob lc_model --knob eye_substeps -o " + tmp.str("out"));
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  const fs::path out = tmp.path() / "out";
  std::vector<std::string> header;
  const auto rows = read_csv(out / "sweep.csv", &header);
  std::vector<std::string> labels;
  for (const auto& row : rows) {
    if (row.at("knob") == "lc_model") labels.push_back(row.at("value_label"));
    if (row.at("knob") == "eye_substeps") {
      EXPECT_EQ(row.at("value_label"), row.at("value"));
    }
  }
  EXPECT_EQ(labels, trm::cli::lc_model_names());
  std::ifstream md(out / "sweep.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("| **0 first** (base) |"), std::string::npos);
  EXPECT_NE(text.find("| 3 second+overdrive |"), std::string::npos);
  std::ifstream js(out / "report.json");
  const auto report = nlohmann::json::parse(js);
  ASSERT_EQ(report["pareto"].size(), 4u);
  EXPECT_EQ(report["pareto"][3]["chart"], "LC model: error vs eye-model time");
  for (const auto& point : report["pareto"][3]["front"]) EXPECT_EQ(point["knob"], "lc_model");
  EXPECT_EQ(report["knobs"][0]["points"][3]["value_label"], "second+overdrive");
  EXPECT_EQ(trm::media::read_image((out / "sweep_pareto.png").string(), cv::IMREAD_COLOR).cols, 2400);
  const auto list = run_trm("sweep --list-knobs");
  ASSERT_EQ(list.exit_code, 0) << list.output;
  EXPECT_NE(list.output.find("lc_model"), std::string::npos) << list.output;
  EXPECT_NE(list.output.find("3=second+overdrive"), std::string::npos) << list.output;
  EXPECT_NE(list.output.find("(LCD panel only)"), std::string::npos) << list.output;
}

