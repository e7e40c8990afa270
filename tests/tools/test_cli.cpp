// End-to-end checks of the `trm` command line: exit codes, messages, outputs written whole or not at all.
#include "trm_process.hpp"

#include "trm/media.hpp"
#include "trm/metrics.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using Result = trm::test::TrmResult;
using trm::test::run_trm;

// A scratch directory for one test, removed afterwards.
class CliTempDir : public trm::test::ScratchDir {
 public:
  CliTempDir() : ScratchDir("trm-cli-") {}
};

// Writes n random 8-bit sRGB frames (RGB noise, deterministic) as frame_000.png ...
void write_frames(const fs::path& dir, int n, int width, int height, bool same = false) {
  fs::create_directories(dir);
  cv::RNG rng(1234);
  cv::Mat frame(height, width, CV_8UC3);
  for (int i = 0; i < n; ++i) {
    if (i == 0 || !same) rng.fill(frame, cv::RNG::UNIFORM, 0, 256);
    char name[32];
    std::snprintf(name, sizeof name, "frame_%03d.png", i);
    ASSERT_TRUE(trm::media::write_image((dir / name).string(), frame));
  }
}

std::vector<nlohmann::json> read_json_lines(const fs::path& path) {
  std::vector<nlohmann::json> records;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) records.push_back(nlohmann::json::parse(line));
  return records;
}

// Drive codes two decodes wrote (drive8_NNNN.png), compared here rather than taken from trm's own report. A view
// missing from both (lost by the link) is skipped.
struct DriveAgreement {
  std::int64_t codes = 0, identical = 0;
  double max_lsb = 0.0;
};

DriveAgreement compare_drive_files(const fs::path& dir, const fs::path& reference_dir, int frames) {
  DriveAgreement a;
  for (int t = 0; t < frames; ++t) {
    char name[32];
    std::snprintf(name, sizeof name, "drive8_%04d.png", t);
    const cv::Mat codes = trm::media::read_image((dir / name).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat reference = trm::media::read_image((reference_dir / name).string(), cv::IMREAD_UNCHANGED);
    if (codes.empty() && reference.empty()) continue;
    if (codes.empty() || reference.empty()) {
      ADD_FAILURE() << name << " written by only one of " << dir << " and " << reference_dir;
      continue;
    }
    cv::Mat difference;
    cv::absdiff(codes, reference, difference);
    const auto n = static_cast<std::int64_t>(difference.total()) * difference.channels();
    a.codes += n;
    a.identical += n - cv::countNonZero(difference.reshape(1));
    a.max_lsb = std::max(a.max_lsb, cv::norm(difference, cv::NORM_INF));
  }
  return a;
}

bool no_partial_left(const fs::path& parent) {
  for (const auto& entry : fs::directory_iterator(parent)) {
    if (entry.path().filename().string().find(".partial-") != std::string::npos) return false;
  }
  return true;
}

}  // namespace

TEST(Cli, VersionAndHelp) {
  const Result version = run_trm("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.output.find("trm "), std::string::npos);
  const Result help = run_trm("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("run"), std::string::npos);
  EXPECT_NE(help.output.find("decode"), std::string::npos);
}

TEST(Cli, UnknownSubcommandOrOptionFails) {
  EXPECT_NE(run_trm("frobnicate").exit_code, 0);
  EXPECT_NE(run_trm("run --no-such-option").exit_code, 0);
}

TEST(Cli, DecodeWritesDriveFramesAtBothDepths) {
  CliTempDir tmp;
  write_frames(tmp.path() / "in", 4, 17, 11);
  const Result r8 = run_trm("decode --input '" + tmp.str("in/frame_*.png") + "' --out " + tmp.str("out8"));
  ASSERT_EQ(r8.exit_code, 0) << r8.output;
  for (int t = 0; t < 4; ++t) {
    char name[32];
    std::snprintf(name, sizeof name, "drive8_%04d.png", t);
    const cv::Mat codes = trm::media::read_image(tmp.str("out8/") + name, cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(codes.empty()) << name;
    EXPECT_EQ(codes.depth(), CV_8U);
    EXPECT_EQ(codes.cols, 17);
    EXPECT_EQ(codes.rows, 11);
    std::snprintf(name, sizeof name, "drive_%04d.png", t);
    const cv::Mat drive = trm::media::read_image(tmp.str("out8/") + name, cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(drive.empty()) << name;
    EXPECT_EQ(drive.depth(), CV_16U);
    // The 8-bit codes are the 16-bit drive quantised: they agree to within one 8-bit step.
    cv::Mat drive_as_8;
    drive.convertTo(drive_as_8, CV_64F, 255.0 / 65535.0);
    cv::Mat codes_d;
    codes.convertTo(codes_d, CV_64F);
    EXPECT_LE(cv::norm(drive_as_8, codes_d, cv::NORM_INF), 0.5 + 255.0 / 65535.0);
  }
  EXPECT_TRUE(fs::exists(tmp.path() / "out8" / "report.json"));

  const Result r10 =
      run_trm("decode --input '" + tmp.str("in/frame_*.png") + "' --out " + tmp.str("out10") + " --bits 10");
  ASSERT_EQ(r10.exit_code, 0) << r10.output;
  const cv::Mat codes10 = trm::media::read_image(tmp.str("out10/drive10_0001.png"), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(codes10.empty());
  EXPECT_EQ(codes10.depth(), CV_16U);
  double max_code = 0;
  cv::minMaxLoc(codes10.reshape(1), nullptr, &max_code);
  EXPECT_LE(max_code, 1023.0);
}

TEST(Cli, DecodeBadInputsFailCleanlyWithoutPartialOutput) {
  CliTempDir tmp;
  write_frames(tmp.path() / "in", 2, 8, 6);
  const std::string input = " --input '" + tmp.str("in/frame_*.png") + "'";
  struct Case {
    std::string args;
    std::string message;  // a fragment the error must contain
  };
  fs::create_directories(tmp.path() / "mixed");
  write_frames(tmp.path() / "mixed", 1, 8, 6);
  ASSERT_TRUE(trm::media::write_image(tmp.str("mixed/frame_001.png"), cv::Mat(7, 8, CV_8UC3, cv::Scalar::all(3))));
  fs::create_directories(tmp.path() / "notimage");
  { std::ofstream(tmp.path() / "notimage" / "frame_000.png") << "this is not a PNG"; }

  const std::vector<Case> cases = {
      {"decode --input '" + tmp.str("nothing/frame_*.png") + "' --out " + tmp.str("o1"), "frame_*"},
      {"decode --input '" + tmp.str("mixed/frame_*.png") + "' --out " + tmp.str("o2"), "frame_001"},
      {"decode --input '" + tmp.str("notimage/frame_*.png") + "' --out " + tmp.str("o3"), "frame_000"},
      {"decode" + input + " --out " + tmp.str("o4") + " --reduction 0", "reduction"},
      {"decode" + input + " --out " + tmp.str("o5") + " --reduction 1.5", "reduction"},
      {"decode" + input + " --out " + tmp.str("o6") + " --sigma -1", "sigma"},
      {"decode" + input + " --out " + tmp.str("o7") + " --panel plasma", "plasma"},
      {"decode" + input + " --out " + tmp.str("o8") + " --bits 12", "bits"},
      {"decode" + input + " --out " + tmp.str("o9") + " --impl magic", "magic"},
      {"run --scene nosuchscene --out " + tmp.str("o10"), "nosuchscene"},
      {"run --frames 2 --size 0x4 --out " + tmp.str("o11"), "size"},
  };
  for (const Case& c : cases) {
    const Result r = run_trm(c.args);
    EXPECT_NE(r.exit_code, 0) << c.args;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_EQ(r.output.find("terminate called"), std::string::npos) << r.output;
  }
  for (const char* out : {"o1", "o2", "o3", "o4", "o5", "o6", "o7", "o8", "o9", "o10", "o11"}) {
    EXPECT_FALSE(fs::exists(tmp.path() / out)) << out;
  }
  EXPECT_TRUE(no_partial_left(tmp.path()));
}

TEST(Cli, RunRefusesToReplaceAForeignDirectory) {
  CliTempDir tmp;
  fs::create_directories(tmp.path() / "precious");
  { std::ofstream(tmp.path() / "precious" / "thesis.tex") << "do not delete"; }
  const Result r = run_trm("run --frames 2 --size 16x12 --out " + tmp.str("precious"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(fs::exists(tmp.path() / "precious" / "thesis.tex"));
  EXPECT_TRUE(no_partial_left(tmp.path()));
}

TEST(Cli, RunWritesReportAndPreviews) {
  CliTempDir tmp;
  const Result r = run_trm("run --scene discs --frames 4 --size 48x40 --out " + tmp.str("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(tmp.path() / "out" / "report.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["summary"]["views"], 4);
  EXPECT_EQ(report["summary"]["pairs"], 2);
  EXPECT_EQ(report["records"]["views"], "views.jsonl");
  EXPECT_EQ(report["records"]["pairs"], "pairs.jsonl");
  EXPECT_FALSE(report.contains("frames"));
  // One JSON object per line: the per-view records, then the per-pair ones.
  const auto views = read_json_lines(tmp.path() / "out" / "views.jsonl");
  ASSERT_EQ(views.size(), 4u);
  for (int t = 0; t < 4; ++t) {
    EXPECT_EQ(views[t]["t"], t);
    EXPECT_EQ(views[t]["parity"], t % 2 == 0 ? "full" : "reduced");
    EXPECT_EQ(views[t]["sent_size"][0], t % 2 == 0 ? 48 : 24);
    EXPECT_TRUE(views[t].contains("vs_reference"));
    EXPECT_TRUE(views[t].contains("fixed_point_events"));
  }
  const auto pairs = read_json_lines(tmp.path() / "out" / "pairs.jsonl");
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[1]["t"][0], 2);
  EXPECT_EQ(pairs[1]["t"][1], 3);
  EXPECT_TRUE(pairs[1].contains("psnr_db"));
  EXPECT_EQ(report["parameters"]["size"][0], 48);
  EXPECT_EQ(report["parameters"]["reduced_size"][0], 24);
  // Pixel ratio over whole pairs: (W H + w h) / (2 W H) = (48*40 + 24*20) / (2*48*40) = 0.625.
  EXPECT_DOUBLE_EQ(report["summary"]["pixel_ratio"].get<double>(), 0.625);
  // The skips' traffic saved, from the run's own counters at the default formats (residual 30 bits, 8-bit link and
  // drive, x_{t-1} sQ3.28): every residual line 3 * 48 * 30 bits, every static line two d_{t-1} rows of 3 * 24 * 8
  // bits, and on the OLED every view's LCD stores, 3 * 48 * 40 samples * (8 + 2 * 31) bits.
  const auto& events = report["summary"]["fixed_point_events"];
  const auto& saved = events["traffic_saved_bytes"];
  EXPECT_DOUBLE_EQ(saved["residual_write"].get<double>(),
                   events["skipped"]["residual_write_lines"].get<double>() * 3 * 48 * 30 / 8);
  EXPECT_DOUBLE_EQ(saved["residual_read"].get<double>(),
                   events["skipped"]["residual_read_lines"].get<double>() * 3 * 48 * 30 / 8);
  EXPECT_DOUBLE_EQ(saved["previous_low_read"].get<double>(),
                   events["skipped"]["motion_test_lines"].get<double>() * 2 * 3 * 24 * 8 / 8);
  EXPECT_DOUBLE_EQ(saved["lcd_stores"].get<double>(), 4.0 * 3 * 48 * 40 * 70 / 8);
  EXPECT_DOUBLE_EQ(saved["total"].get<double>(), saved["residual_write"].get<double>() +
                                                     saved["residual_read"].get<double>() +
                                                     saved["previous_low_read"].get<double>() +
                                                     saved["lcd_stores"].get<double>());
  EXPECT_NE(r.output.find("off-chip traffic saved per view"), std::string::npos) << r.output;
  for (const char* name : {"pair_sent_full.png", "pair_sent_reduced.png", "pair_shown_beta.png",
                           "pair_shown_alpha.png", "pair_perceived.png", "pair_full_rate_reference.png"}) {
    EXPECT_TRUE(fs::exists(tmp.path() / "out" / name)) << name;
  }
  const cv::Mat reduced = trm::media::read_image(tmp.str("out/pair_sent_reduced.png"), cv::IMREAD_COLOR);
  EXPECT_EQ(reduced.cols, 24);
  EXPECT_EQ(reduced.rows, 20);
  // Running again over our own output replaces it.
  EXPECT_EQ(run_trm("run --scene discs --frames 2 --size 48x40 --out " + tmp.str("out")).exit_code, 0);
}

TEST(Cli, LowRefreshWarnsButRuns) {
  CliTempDir tmp;
  const Result r = run_trm("run --frames 2 --size 16x12 --refresh 60 --out " + tmp.str("out"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("flicker"), std::string::npos);
}

TEST(Cli, LosslessCurveFallsWithTheReduction) {
  CliTempDir tmp;
  const Result r = run_trm("lossless --scene panorama --size 96x80 --frames 4 --reduction 1 0.5 0.25 --out " +
                           tmp.str("ll"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(tmp.path() / "ll" / "report.json");
  const auto report = nlohmann::json::parse(in);
  const auto& row = report["results"][0];
  const double full = row["full_rate_bpp"].get<double>();
  const double r1 = row["trm_bpp"]["1.000000"].get<double>();
  const double r05 = row["trm_bpp"]["0.500000"].get<double>();
  const double r025 = row["trm_bpp"]["0.250000"].get<double>();
  // Natural texture: the reduced frames code to fewer bits the smaller they are, and below full rate.
  EXPECT_GT(full, 0.0);
  EXPECT_LT(r05, r1);
  EXPECT_LT(r025, r05);
  EXPECT_LT(r05, full);
  EXPECT_NE(run_trm("lossless --scene panorama --reduction 0 --size 8x8").exit_code, 0);
}

TEST(Cli, RunHoldsTheFixedPointDecoderToTheReference) {
  CliTempDir tmp;
  // A fault-free link changes nothing but records the stream, so the same views can be decoded again apart.
  const Result r = run_trm("run --scene panorama --frames 4 --size 64x48 --link dp1.4 --out " + tmp.str("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(tmp.path() / "out" / "report.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["parameters"]["impl"], "fixed");
  const auto& vs = report["summary"]["vs_reference"];
  EXPECT_EQ(vs["codes_compared"].get<std::int64_t>(), 4 * 64 * 48 * 3);

  // The report's comparison against one made here from the drive codes each decoder writes on its own.
  for (const char* impl : {"reference", "fixed"}) {
    const Result d = run_trm("decode --capture " + tmp.str("out/link.trmcap") + " --impl " + impl + " --out " +
                             tmp.str(impl));
    ASSERT_EQ(d.exit_code, 0) << impl << "\n" << d.output;
  }
  const DriveAgreement files = compare_drive_files(tmp.path() / "fixed", tmp.path() / "reference", 4);
  EXPECT_EQ(files.codes, vs["codes_compared"].get<std::int64_t>());
  EXPECT_DOUBLE_EQ(static_cast<double>(files.identical) / static_cast<double>(files.codes),
                   vs["identical_fraction"].get<double>());
  EXPECT_EQ(files.max_lsb, vs["max_lsb"].get<double>());
  EXPECT_TRUE(trm::kReferenceAgreementCriterion.met_by(files.identical, files.codes, files.max_lsb));
  EXPECT_TRUE(vs["meets_criterion"].get<bool>());
  EXPECT_GT(report["hardware"]["total_bits"].get<std::int64_t>(), 0);
  EXPECT_NE(r.output.find("vs reference"), std::string::npos);
}

TEST(Cli, DecodeWithEveryImplementationAgrees) {
  CliTempDir tmp;
  write_frames(tmp.path() / "in", 4, 33, 21);
  const std::string input = "decode --input '" + tmp.str("in/frame_*.png") + "' --out ";
  for (const char* impl : {"reference", "fixed", "fixed-frame"}) {
    const Result r = run_trm(input + tmp.str(impl) + " --impl " + impl);
    ASSERT_EQ(r.exit_code, 0) << impl << "\n" << r.output;
  }
  // The two schedules of the fixed-point arithmetic are bit-identical; both meet the criterion against the reference.
  const DriveAgreement schedules = compare_drive_files(tmp.path() / "fixed", tmp.path() / "fixed-frame", 4);
  EXPECT_EQ(schedules.codes, 4 * 33 * 21 * 3);
  EXPECT_EQ(schedules.identical, schedules.codes);
  const DriveAgreement files = compare_drive_files(tmp.path() / "fixed", tmp.path() / "reference", 4);
  EXPECT_EQ(files.codes, 4 * 33 * 21 * 3);
  EXPECT_TRUE(trm::kReferenceAgreementCriterion.met_by(files.identical, files.codes, files.max_lsb))
      << files.identical << " of " << files.codes << " codes identical, max " << files.max_lsb << " LSB";
}

TEST(Cli, RunWithLinkFaultsDecodesWithTheFixedPointModel) {
  // Faults no longer switch the decoder: the fixed-point model conceals lost lines itself, the reference runs beside
  // it on the same damaged views, and the comparison is reported as on a clean link.
  CliTempDir tmp;
  const Result r = run_trm("run --frames 6 --size 48x32 --ber 2e-4 --drop 0.02 --seed 5 --impl fixed --out " +
                           tmp.str("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("decoding with --impl reference"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("vs reference"), std::string::npos) << r.output;
  std::ifstream in(tmp.path() / "out" / "report.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["parameters"]["impl"], "fixed");
  EXPECT_GT(report["link"]["concealed_lines"].get<std::int64_t>(), 0);
  const auto& vs = report["summary"]["vs_reference"];
  EXPECT_EQ(vs["codes_compared"].get<std::int64_t>(), 6 * 48 * 32 * 3);
  EXPECT_TRUE(vs["meets_criterion"].get<bool>());
  EXPECT_FALSE(report["hardware"]["concealment"].get<std::string>().empty());

  // Its capture decodes with either fixed-point schedule to the same drive codes, which meet the criterion against
  // the reference's decode of the same damaged views.
  for (const char* impl : {"reference", "fixed", "fixed-frame"}) {
    const Result d = run_trm("decode --capture " + tmp.str("out/link.trmcap") + " --impl " + impl + " --out " +
                             tmp.str(impl));
    ASSERT_EQ(d.exit_code, 0) << impl << "\n" << d.output;
  }
  for (int t = 0; t < 6; ++t) {
    char name[32];
    std::snprintf(name, sizeof name, "/drive8_%04d.png", t);
    const cv::Mat streaming = trm::media::read_image(tmp.str("fixed") + name, cv::IMREAD_UNCHANGED);
    const cv::Mat frame = trm::media::read_image(tmp.str("fixed-frame") + name, cv::IMREAD_UNCHANGED);
    if (streaming.empty() && frame.empty()) continue;  // a view the link lost entirely is not in the capture
    ASSERT_FALSE(streaming.empty() || frame.empty()) << t;
    EXPECT_EQ(cv::norm(streaming, frame, cv::NORM_INF), 0.0) << t;
  }
  const DriveAgreement files = compare_drive_files(tmp.path() / "fixed", tmp.path() / "reference", 6);
  EXPECT_GT(files.codes, 0);
  EXPECT_TRUE(trm::kReferenceAgreementCriterion.met_by(files.identical, files.codes, files.max_lsb))
      << files.identical << " of " << files.codes << " codes identical, max " << files.max_lsb << " LSB";
}

TEST(Cli, CaptureReplaysIntoDecodeAndFeed) {
  CliTempDir tmp;
  const Result run = run_trm("run --frames 4 --size 32x24 --link dp1.2 --ber 1e-5 --seed 3 --out " + tmp.str("run"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  ASSERT_TRUE(fs::exists(tmp.path() / "run" / "link.trmcap"));
  ASSERT_TRUE(fs::exists(tmp.path() / "run" / "frames.csv"));
  const cv::Mat bits_plot = trm::media::read_image(tmp.str("run/link_bits.png"), cv::IMREAD_COLOR);
  ASSERT_FALSE(bits_plot.empty());
  EXPECT_EQ(bits_plot.cols, 1200);
  EXPECT_EQ(bits_plot.rows, 640);
  const Result decode = run_trm("decode --capture " + tmp.str("run/link.trmcap") + " --out " + tmp.str("dec"));
  ASSERT_EQ(decode.exit_code, 0) << decode.output;
  EXPECT_TRUE(fs::exists(tmp.path() / "dec" / "drive8_0003.png"));
  const Result feed = run_trm("feed --capture " + tmp.str("run/link.trmcap") + " --file " + tmp.str("rig.bin") + " --fps 0");
  ASSERT_EQ(feed.exit_code, 0) << feed.output;
  // Four 32x24 8-bit RGB frames went out, with protocol framing around them.
  EXPECT_GT(fs::file_size(tmp.path() / "rig.bin"), 4u * 32 * 24 * 3);

  // A truncated capture is refused with its name, and leaves no output behind.
  const auto size = fs::file_size(tmp.path() / "run" / "link.trmcap");
  fs::copy_file(tmp.path() / "run" / "link.trmcap", tmp.path() / "cut.trmcap");
  fs::resize_file(tmp.path() / "cut.trmcap", size / 2);
  const Result cut = run_trm("decode --capture " + tmp.str("cut.trmcap") + " --out " + tmp.str("cutdec"));
  EXPECT_NE(cut.exit_code, 0);
  EXPECT_NE(cut.output.find("cut.trmcap"), std::string::npos) << cut.output;
  EXPECT_FALSE(fs::exists(tmp.path() / "cutdec"));
  EXPECT_NE(run_trm("run --frames 2 --size 8x8 --link custom:0:0.8 --out " + tmp.str("zero")).exit_code, 0);
}

// Every display method goes over the same link, faults included, and says what it rendered and sent.
TEST(Cli, EveryMethodRunsOverAFaultyLinkAndReportsItsPixelsAndPayloadPerLinkFrame) {
  CliTempDir tmp;
  const Result list = run_trm("methods");
  ASSERT_EQ(list.exit_code, 0) << list.output;
  const std::vector<std::pair<std::string, double>> methods = {
      {"trm", 0.625}, {"full", 1.0}, {"half-rate", 0.5}, {"interlace", 0.5}, {"interlace:double", 0.5}, {"bfi", 0.5},
      {"ncsfi", 0.625}, {"didyk", 1.0}, {"didyk:2-hold", 0.5}, {"kim", 1.0}, {"kim-trm", 0.625},
      {"reprojection", 1.0}};
  for (const auto& [method, sent_ratio] : methods) {
    EXPECT_NE(list.output.find(method.substr(0, method.find(':'))), std::string::npos) << method;
    const std::string out = tmp.str("run-" + method.substr(0, method.find(':')) + std::to_string(method.size()));
    const Result run = run_trm("run --method " + method + " --frames 6 --size 32x24 --link dp1.2 --drop 0.02 --seed 5 --out " + out);
    ASSERT_EQ(run.exit_code, 0) << method << "\n" << run.output;
    std::ifstream in(out + "/report.json");
    const nlohmann::json report = nlohmann::json::parse(in);
    EXPECT_EQ(report["parameters"]["method"], method);
    EXPECT_EQ(report["link"]["method"], method);
    EXPECT_DOUBLE_EQ(report["summary"]["pixels_sent_ratio"].get<double>(), sent_ratio) << method;
    EXPECT_GT(report["link"]["average_payload_bits"].get<double>(), 0.0) << method;
    // frames.csv: one row per link frame, each naming the method, payload bits as carried.
    std::ifstream csv(out + "/frames.csv");
    std::string header, row;
    std::getline(csv, header);
    EXPECT_EQ(header.substr(header.rfind(',') + 1), "method");
    int rows = 0;
    while (std::getline(csv, row)) {
      EXPECT_EQ(row.substr(row.rfind(',') + 1), method) << row;
      ++rows;
    }
    EXPECT_EQ(rows, 6) << method;
    // The plain-frame methods are decoded by the reference; TRM's family by the hardware model.
    const bool fixed = method == "trm" || method == "ncsfi" || method == "kim-trm";
    EXPECT_EQ(report["parameters"]["impl"], fixed ? "fixed" : "reference") << method;
  }
}

// A capture records its method; replay tells slots the method never sent from views the link lost.
TEST(Cli, CaptureOfAHalfRateRunReplaysWithItsUnsentSlots) {
  CliTempDir tmp;
  const Result run = run_trm("run --method half-rate --frames 6 --size 32x24 --link dp1.2 --out " + tmp.str("run"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const Result decode = run_trm("decode --capture " + tmp.str("run/link.trmcap") + " --out " + tmp.str("dec"));
  ASSERT_EQ(decode.exit_code, 0) << decode.output;
  const auto views = read_json_lines(tmp.path() / "dec" / "views.jsonl");
  ASSERT_EQ(views.size(), 6u);
  for (const auto& v : views) {
    const bool sent = v["t"].get<int>() % 2 == 0;
    EXPECT_EQ(v["sent"], sent) << v.dump();
    EXPECT_EQ(v["lost"], false) << v.dump();
  }
  // The repeat is the rendered frame again, code for code.
  const cv::Mat shown = trm::media::read_image(tmp.str("dec/drive8_0002.png"), cv::IMREAD_UNCHANGED);
  const cv::Mat repeated = trm::media::read_image(tmp.str("dec/drive8_0003.png"), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(shown.empty() || repeated.empty());
  EXPECT_EQ(cv::norm(shown, repeated, cv::NORM_INF), 0.0);
  std::ifstream in(tmp.str("dec/report.json"));
  EXPECT_EQ(nlohmann::json::parse(in)["parameters"]["method"], "half-rate");
  // The fixed-point decoder is refused for a plain-frame capture, with the capture's name.
  const Result fixed = run_trm("decode --impl fixed --capture " + tmp.str("run/link.trmcap") + " --out " + tmp.str("f"));
  EXPECT_NE(fixed.exit_code, 0);
  EXPECT_NE(fixed.output.find("half-rate"), std::string::npos) << fixed.output;
  EXPECT_FALSE(fs::exists(tmp.path() / "f"));
}

// `trm compare`: every method on the same frames; figures with analytic answers checked, the rest present and finite.
TEST(Cli, CompareShowsNcsfiGhostingGrowWithSpeed) {
  // NCSFI's blurred frame shows the frame before (TRM paper Sec. 8): the faster the disc, the farther that ghost
  // lies from where full rate puts it, so its energy against full rate grows with speed (measured 125, 196, 244).
  CliTempDir tmp;
  double previous = 0.0;
  for (const int speed : {5, 20, 60}) {
    const std::string out = tmp.str("ncsfi" + std::to_string(speed));
    const Result run = run_trm("compare --methods ncsfi,trm --scene discs --speed " + std::to_string(speed) +
                               " --size 216x120 --frames 8 --out " + out);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    std::ifstream in(out + "/report.json");
    const nlohmann::json report = nlohmann::json::parse(in);
    std::map<std::string, double> energy;
    for (const auto& m : report["methods"]) {
      energy[m["method"].get<std::string>()] = m["energy_vs_full_rate"].get<double>();
    }
    EXPECT_GT(energy["ncsfi"], previous) << speed << " deg/s";
    std::printf("[ ncsfi ] %d deg/s: energy vs full rate %.2f\n", speed, energy["ncsfi"]);
    previous = energy["ncsfi"];
  }
}

TEST(Cli, CompareMeasuresEveryMethodOnTheSameFrames) {
  CliTempDir tmp;
  const Result run = run_trm("compare --scene panorama --size 216x120 --frames 8 --out " + tmp.str("cmp"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const char* name : {"compare.md", "compare.csv", "report.json"}) {
    EXPECT_TRUE(fs::exists(tmp.path() / "cmp" / name)) << name;
  }
  std::ifstream in(tmp.str("cmp/report.json"));
  const nlohmann::json report = nlohmann::json::parse(in);
  std::map<std::string, nlohmann::json> by_method;
  for (const auto& m : report["methods"]) by_method[m["method"].get<std::string>()] = m;
  ASSERT_EQ(by_method.size(), 10u);
  // Pixels: exact fractions of full rate (216x120 at r = 1/2 reduces to 108x60).
  EXPECT_DOUBLE_EQ(by_method["trm"]["pixels_rendered_saved_percent"].get<double>(), 37.5);
  EXPECT_DOUBLE_EQ(by_method["ncsfi"]["pixels_rendered_saved_percent"].get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(by_method["ncsfi"]["pixels_sent_saved_percent"].get<double>(), 37.5);
  for (const char* half : {"half-rate", "interlace", "bfi"}) {
    EXPECT_DOUBLE_EQ(by_method[half]["pixels_sent_saved_percent"].get<double>(), 50.0) << half;
  }
  EXPECT_DOUBLE_EQ(by_method["full"]["pixels_sent_saved_percent"].get<double>(), 0.0);
  // Didyk renders frames 0, 3 and 6 of the 8 and morphs the others GPU-side: every frame crosses the link whole.
  EXPECT_DOUBLE_EQ(by_method["didyk"]["pixels_rendered_saved_percent"].get<double>(), 62.5);
  EXPECT_DOUBLE_EQ(by_method["didyk"]["pixels_sent_saved_percent"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(by_method["kim"]["pixels_rendered_saved_percent"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(by_method["kim-trm"]["pixels_sent_saved_percent"].get<double>(), 37.5);
  EXPECT_DOUBLE_EQ(by_method["reprojection"]["pixels_rendered_saved_percent"].get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(by_method["reprojection"]["pixels_sent_saved_percent"].get<double>(), 0.0);
  // The pan moves the world, not the head: Kim's dynamic map leaves it alone and there is no head rotation to
  // reproject, so kim shows what full rate shows and reprojection what half rate shows.
  EXPECT_EQ(by_method["kim"]["energy_vs_full_rate"].get<double>(), 0.0);
  EXPECT_EQ(by_method["kim"]["mtcd"].get<double>(), by_method["full"]["mtcd"].get<double>());
  EXPECT_EQ(by_method["reprojection"]["energy_vs_continuous"].get<double>(),
            by_method["half-rate"]["energy_vs_continuous"].get<double>());
  // Light: black frames and black rows halve it; a repeat does not flicker; full rate is its own reference.
  EXPECT_NEAR(by_method["bfi"]["luminance_percent"].get<double>(), 50.0, 0.5);
  EXPECT_NEAR(by_method["interlace"]["luminance_percent"].get<double>(), 50.0, 0.5);
  EXPECT_NEAR(by_method["trm"]["luminance_percent"].get<double>(), 100.0, 1.0);
  EXPECT_EQ(by_method["half-rate"]["flicker_contrast"].get<double>(), 0.0);
  EXPECT_NEAR(by_method["bfi"]["flicker_contrast"].get<double>(), 1.0, 1e-12);
  EXPECT_EQ(by_method["full"]["energy_vs_full_rate"].get<double>(), 0.0);
  EXPECT_EQ(by_method["full"]["judder_vs_full_rate"].get<double>(), 0.0);

  EXPECT_GT(by_method["full"]["mean_pair_ssim"].get<double>(), by_method["bfi"]["mean_pair_ssim"].get<double>());
  EXPECT_LE(by_method["full"]["mean_pair_ssim"].get<double>(), 1.0);
  EXPECT_GT(by_method["trm"]["energy_vs_full_rate"].get<double>(), 0.0);
  // Pursuit of the pan: the half-rate hold blurs more than full rate against continuous motion, black frames less.
  EXPECT_GT(report["eye"]["target_velocity_deg_s"].get<double>() * report["eye"]["target_velocity_deg_s"].get<double>(), 0.0);
  EXPECT_GT(by_method["half-rate"]["energy_vs_continuous"].get<double>(), by_method["full"]["energy_vs_continuous"].get<double>());
  EXPECT_LT(by_method["bfi"]["energy_vs_continuous"].get<double>(), by_method["full"]["energy_vs_continuous"].get<double>());
  // The panorama's line has no sharp edge: no blur figure rather than the width of a texture's gradient.
  EXPECT_TRUE(report["eye"]["continuous_blur_arcmin"].is_null());
  for (const auto& [name, m] : by_method) {
    EXPECT_TRUE(m["motion_blur_arcmin"].is_null()) << name;
    EXPECT_GE(m["judder"].get<double>(), 0.0) << name;
    // Fig. 12 of every method: four panels of the x-t view, written whole.
    const cv::Mat figure = trm::media::read_image(tmp.str("cmp/fig12_" + name + ".png"), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(figure.empty()) << name;
    EXPECT_EQ(figure.channels(), 3) << name;
    EXPECT_GT(figure.cols, 4 * figure.rows / 4) << name;
  }
  // Flicker at fixed gaze: black frames flicker more visibly than anything else, and up to a higher refresh rate.
  for (const char* other : {"trm", "full", "half-rate", "ncsfi"}) {
    EXPECT_GT(by_method["bfi"]["flicker_visibility"].get<double>(), by_method[other]["flicker_visibility"].get<double>()) << other;
  }
  EXPECT_EQ(by_method["half-rate"]["flicker_visibility"].get<double>(), 0.0);
  EXPECT_GT(by_method["bfi"]["flicker_invisible_from_hz"].get<double>(), by_method["full"]["flicker_invisible_from_hz"].get<double>());
  // Blur under exact pursuit of a disc's sharp edge: the repeat holds it twice as long as full rate, black frames
  // do not lengthen a flash; no method is sharper than the disc moving continuously.
  const Result discs = run_trm(
      "compare --methods full,half-rate,bfi --scene discs --speed 20 --size 216x120 --frames 8 --out " + tmp.str("discs"));
  ASSERT_EQ(discs.exit_code, 0) << discs.output;
  std::ifstream in_discs(tmp.str("discs/report.json"));
  const nlohmann::json disc_report = nlohmann::json::parse(in_discs);
  std::map<std::string, double> blur;
  std::map<std::string, double> judder, extra_judder;
  for (const auto& m : disc_report["methods"]) {
    blur[m["method"].get<std::string>()] = m["motion_blur_arcmin"].get<double>();
    judder[m["method"].get<std::string>()] = m["judder"].get<double>();
    extra_judder[m["method"].get<std::string>()] = m["judder_vs_full_rate"].get<double>();
  }
  // The repeat shows the disc in one place for two frames while the eye moves on: judder beyond full rate's (the
  // absolute figure of every method also holds the sub-pixel phase of each frame's disc, full rate's included).
  EXPECT_GT(extra_judder["half-rate"], 0.0);
  for (const auto& [name, value] : judder) EXPECT_GT(value, 0.0) << name;
  EXPECT_EQ(extra_judder["full"], 0.0);
  const double continuous_blur = disc_report["eye"]["continuous_blur_arcmin"].get<double>();
  EXPECT_NEAR(std::abs(disc_report["eye"]["target_velocity_deg_s"].get<double>()), 20.0, 1e-9);
  EXPECT_GT(blur["half-rate"], 1.5 * blur["full"]);
  // Each flash is as short as full rate's; the averages differ by the disc's sub-pixel phase in the frames each
  // one lights (4 of 8 frames against all 8).
  EXPECT_NEAR(blur["bfi"], blur["full"], 0.15 * blur["full"]);
  for (const auto& [name, width] : blur) EXPECT_GE(width, continuous_blur - 1e-9) << name;
  // A still scene: TRM keeps the full light. Its artefact energy against full rate is the 8-bit codes' floor
  // (StaticTrm.* in static_energy_test.cpp takes it apart: 0 in the pair-mean percept, the rest the alternation and
  // the two methods' rounding, bounded by their sum, with the very metric this command applies).
  const Result still = run_trm("compare --methods trm,full --scene static --size 216x120 --frames 8 --out " +
                               tmp.str("still"));
  ASSERT_EQ(still.exit_code, 0) << still.output;
  std::ifstream in_still(tmp.str("still/report.json"));
  const nlohmann::json still_report = nlohmann::json::parse(in_still);
  std::map<std::string, nlohmann::json> still_by;
  for (const auto& m : still_report["methods"]) still_by[m["method"].get<std::string>()] = m;
  EXPECT_NEAR(still_by["trm"]["luminance_percent"].get<double>(), 100.0, 0.1);
  EXPECT_GT(still_by["trm"]["energy_vs_full_rate"].get<double>(), 0.0);
  // Nothing moves: full rate has no temporal aliases; TRM's are its alternation of sharp and blurred frames.
  EXPECT_LT(still_by["full"]["judder"].get<double>(), 1e-9);
  EXPECT_GT(still_by["trm"]["judder"].get<double>(), 0.0);
  // A subset runs only what is asked (full rate still measured as the reference, not listed).
  const Result two = run_trm("compare --methods trm,bfi --scene panorama --size 64x48 --frames 4 --out " + tmp.str("two"));
  ASSERT_EQ(two.exit_code, 0) << two.output;
  std::ifstream in_two(tmp.str("two/report.json"));
  EXPECT_EQ(nlohmann::json::parse(in_two)["methods"].size(), 2u);
}

// On a head-rotation scene the eye fixates a world point and follows it through the head poses: on headturn's
// constant 10 deg/s yaw the path is the pinhole's analytic shift of the view's middle column, -f tan(10 deg t), frame
// by frame; a scene that moves its world is pursued at one speed with Eq. 3's lag.
TEST(Cli, CompareEyeFollowsTheHeadPosesFrameByFrame) {
  CliTempDir tmp;
  const Result run =
      run_trm("compare --methods full,reprojection --scene headturn --size 64x48 --frames 6 --out " + tmp.str("turn"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(tmp.str("turn/report.json"));
  const nlohmann::json eye = nlohmann::json::parse(in)["eye"];
  EXPECT_EQ(eye["gaze"], "head-pose fixation");
  const auto& path = eye["path_px"];
  ASSERT_EQ(path.size(), 7u);
  const double kDeg = std::acos(-1.0) / 180.0;
  const double focal = 32.0 / std::tan(50.0 * kDeg);
  for (std::size_t f = 0; f < path.size(); ++f) {
    EXPECT_NEAR(path[f].get<double>(), -focal * std::tan(10.0 * kDeg * static_cast<double>(f) / 90.0), 1e-9) << f;
  }
  // No lag: the eye's mean is the target's, the net travel over the run's duration in the viewer's degrees.
  EXPECT_EQ(eye["eye_velocity_deg_s"].get<double>(), eye["target_velocity_deg_s"].get<double>());
  EXPECT_NEAR(eye["target_velocity_deg_s"].get<double>(), path[6].get<double>() / (6.0 / 90.0) / 11.42, 1e-12);

  const Result discs = run_trm("compare --methods full --scene discs --size 64x48 --frames 4 --out " + tmp.str("discs"));
  ASSERT_EQ(discs.exit_code, 0) << discs.output;
  std::ifstream in_discs(tmp.str("discs/report.json"));
  const nlohmann::json pursued = nlohmann::json::parse(in_discs)["eye"];
  EXPECT_EQ(pursued["gaze"], "pursuit");
  EXPECT_FALSE(pursued.contains("path_px"));
  const double target = pursued["target_velocity_deg_s"].get<double>();
  EXPECT_NEAR(std::abs(pursued["eye_velocity_deg_s"].get<double>()), std::min(0.82 * std::abs(target) + 0.15, 80.0), 1e-12);
}

// Didyk et al.'s Fig. 8: upsampling 40 -> 120 Hz blurs a pursued edge less than native 40 Hz (each rendered frame held
// three frames) and nearly as little as native 120 Hz, on the paper's hold-type LCD.
TEST(Cli, DidykBlursLessThanNativeFortyHertzAndNearlyAsLittleAsOneTwenty) {
  CliTempDir tmp;
  const Result run = run_trm("compare --methods full,didyk,didyk:hold --scene discs --speed 20 --refresh 120 "
                             "--panel lcd --size 216x120 --frames 9 --out " + tmp.str("cmp"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(tmp.str("cmp/report.json"));
  const nlohmann::json report = nlohmann::json::parse(in);
  std::map<std::string, double> blur;
  for (const auto& m : report["methods"]) blur[m["method"].get<std::string>()] = m["motion_blur_arcmin"].get<double>();
  ASSERT_EQ(blur.size(), 3u);
  // Measured 10.47, 12.76 and 25.06 arcmin.
  EXPECT_LT(blur["full"], blur["didyk"]);
  EXPECT_LT(blur["didyk"], blur["didyk:hold"]);
  EXPECT_LT(blur["didyk"] - blur["full"], blur["didyk:hold"] - blur["didyk"]) << "closer to 120 Hz than to 40 Hz";
}
