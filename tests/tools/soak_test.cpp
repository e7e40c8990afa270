// A long run's memory and report.json must not grow with its length: per-view and per-pair records are
// streamed to disk as they are made, and the summary is running statistics. And 10^5 frames through the fixed-point
// decoder keep the residual bounded and a static input's output periodic, bit for bit.
#include "pipeline.hpp"
#include "trm_process.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <ostream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

std::int64_t count_lines(const fs::path& path) {
  std::ifstream in(path);
  std::int64_t lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  return lines;
}

TEST(Soak, LongRunPeakMemoryAndReportStayFlat) {
  // Under AddressSanitizer freed memory waits in a quarantine (256 MB by default) that fills as a run goes on, so
  // peak RSS would grow with the run's length for the sanitizer's sake. This measures the program's memory: the
  // runs go without the quarantine (other builds ignore the option).
  const char* asan = std::getenv("ASAN_OPTIONS");
  const std::string asan_options = (asan != nullptr && *asan != '\0' ? std::string(asan) + ":" : "") + "quarantine_size_mb=0";
  ::setenv("ASAN_OPTIONS", asan_options.c_str(), 1);
  trm::test::ScratchDir tmp("trm-soak-");
  constexpr std::int64_t kShort = 10000, kLong = 100000;  // the 10^5 frames, at 4x4: a few seconds
  const auto run = [&](std::int64_t frames, const std::string& out) {
    return trm::test::run_trm_measured(
        {"run", "--scene", "flash", "--size", "4x4", "--frames", std::to_string(frames), "--out", tmp.str(out)});
  };
  const trm::test::TrmResult short_run = run(kShort, "short");
  ASSERT_EQ(short_run.exit_code, 0) << short_run.output;
  const trm::test::TrmResult long_run = run(kLong, "long");
  ASSERT_EQ(long_run.exit_code, 0) << long_run.output;
  ASSERT_GT(short_run.max_rss_kb, 0);

  // Before the records were streamed, a view cost about 3 KB of memory until the end of the run.
  const double bytes_per_frame =
      static_cast<double>(long_run.max_rss_kb - short_run.max_rss_kb) * 1024.0 / static_cast<double>(kLong - kShort);
  std::cout << "peak RSS " << short_run.max_rss_kb << " kB at " << kShort << " frames, " << long_run.max_rss_kb
            << " kB at " << kLong << ": " << bytes_per_frame << " bytes per frame\n";
  EXPECT_LT(bytes_per_frame, 50.0) << "peak RSS " << short_run.max_rss_kb << " kB at " << kShort << " frames, "
                                   << long_run.max_rss_kb << " kB at " << kLong;

  // Only the digits of the counts and timings differ.
  const auto short_report = fs::file_size(tmp.path() / "short" / "report.json");
  const auto long_report = fs::file_size(tmp.path() / "long" / "report.json");
  EXPECT_LT(long_report, short_report + 64) << short_report << " bytes at " << kShort << " frames, " << long_report
                                            << " at " << kLong;

  // Every record is on disk.
  EXPECT_EQ(count_lines(tmp.path() / "long" / "views.jsonl"), kLong);
  EXPECT_EQ(count_lines(tmp.path() / "long" / "pairs.jsonl"), kLong / 2);
}

// The process's resident set now (pages of /proc/self/statm), in kB; -1 where it cannot be read.
std::int64_t resident_kb() {
  std::ifstream statm("/proc/self/statm");
  std::int64_t size = 0, resident = -1;
  if (!(statm >> size >> resident)) return -1;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

// Under AddressSanitizer freed memory waits in a quarantine that fills as a run goes on, so the resident set grows
// for the sanitizer's sake; the in-process memory check is then left to LeakSanitizer.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kResidentSetMeaningful = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kResidentSetMeaningful = false;
#else
constexpr bool kResidentSetMeaningful = true;
#endif
#else
constexpr bool kResidentSetMeaningful = true;
#endif

// A still scene, the panel and phase it soaks on, and what its residual must be.
struct SoakCase {
  const char* scene;
  const char* panel;
  int phase;
  bool clips;             // beta leaves [0, 1] (or the LCD falls short), so rho is nonzero
  double residual_bound;  // |rho| by construction: OLED beta = 2 I - L in [-1, 2]; LCD shortfalls too (<= 2)
};

void PrintTo(const SoakCase& c, std::ostream* out) { *out << c.scene << " on " << c.panel << " phase " << c.phase; }

class StillSoak : public ::testing::TestWithParam<SoakCase> {};

TEST_P(StillSoak, FixedPointDecoderKeepsTheResidualBoundedAndTheOutputPeriodic) {
  // Every scene repeats with period 2 (flash: black and white; static and checker: one image), so after the first
  // two pairs (the LCD's first frame is solved as if its drive had been held) every view's drive codes must equal
  // those of the view two frames earlier, bit for bit: the state that lives through the run (rho, the kept d_t, the
  // LCD's panel history) cannot drift. The residual is within its bound, the same in the last pair as in the
  // second, and nonzero where it must be: flash on the LCD with white full frames carries the unreachable targets'
  // shortfalls, the Nyquist checkerboard its clipped overshoot; the 4x4 texture never leaves [0, 1]. And memory is
  // flat: the resident set, sampled every 1000 frames after a warm-up of 1000, never exceeds the warm-up's by more
  // than kGrowthBoundKb (a leak of 10 bytes per frame would pass it by the end of the run).
  constexpr std::int64_t kFrames = 100000;
  constexpr std::int64_t kWarmup = 1000, kSampleEvery = 1000, kGrowthBoundKb = 1024;
  const SoakCase& c = GetParam();
  trm::cli::PipelineOptions options;
  options.scene = c.scene;
  options.panel = trm::parse_panel(c.panel);
  options.encoder.phase = c.phase;
  options.width = 4;
  options.height = 4;
  options.frames = kFrames;
  options.impl = "fixed";
  options.impl_given = true;
  std::vector<std::vector<std::uint16_t>> last_two(2);
  std::int64_t views = 0, mismatches = 0;
  double residual_second_pair = -1.0, residual_max = 0.0, residual_last_pair = -1.0;
  std::int64_t warm_kb = -1, peak_after_warmup_kb = -1;
  trm::cli::run_pipeline(options, [&](const trm::cli::DecodedView& view) {
    const cv::Mat& codes = view.decoded->drive_codes;
    ASSERT_TRUE(codes.isContinuous());
    std::vector<std::uint16_t> bits(codes.total() * codes.channels());
    std::memcpy(bits.data(), codes.data, bits.size() * sizeof(std::uint16_t));
    const std::int64_t t = view.slot.index;
    std::vector<std::uint16_t>& two_before = last_two[static_cast<std::size_t>(t % 2)];
    if (t >= 4 && bits != two_before) ++mismatches;
    two_before = std::move(bits);
    const double residual = view.decoded->stats.residual_max_abs;
    residual_max = std::max(residual_max, residual);
    if (t == 4) residual_second_pair = residual;
    if (t == kFrames - 2) residual_last_pair = residual;
    if (t == kWarmup) warm_kb = resident_kb();
    if (t > kWarmup && (t % kSampleEvery == 0 || t == kFrames - 1)) {
      peak_after_warmup_kb = std::max(peak_after_warmup_kb, resident_kb());
    }
    ++views;
  });
  EXPECT_EQ(views, kFrames);
  EXPECT_EQ(mismatches, 0) << c.scene;
  EXPECT_EQ(residual_max > 0.0, c.clips) << c.scene << " max |rho| " << residual_max;
  EXPECT_LE(residual_max, c.residual_bound) << c.scene;
  EXPECT_EQ(residual_last_pair, residual_second_pair) << c.scene;
  ASSERT_GT(warm_kb, 0) << "/proc/self/statm unreadable";
  if (kResidentSetMeaningful) {
    EXPECT_LE(peak_after_warmup_kb - warm_kb, kGrowthBoundKb)
        << c.scene << ": resident " << warm_kb << " kB at frame " << kWarmup << ", up to " << peak_after_warmup_kb
        << " kB after";
  }
  std::cout << c.scene << " on " << c.panel << ": " << kFrames << " frames, max |rho| " << residual_max
            << ", output periodic, resident set " << warm_kb << " kB at frame " << kWarmup << ", at most "
            << peak_after_warmup_kb << " kB after\n";
}

INSTANTIATE_TEST_SUITE_P(FlashStaticChecker, StillSoak,
                         ::testing::Values(SoakCase{"flash", "lcd", 1, true, 2.0}, SoakCase{"static", "vive", 0, false, 1.0},
                                           SoakCase{"checker", "vive", 0, true, 1.0}));

}  // namespace
