// A long run's memory and report.json must not grow with its length: per-view and per-pair records are
// streamed to disk as they are made, and the summary is running statistics.
#include "trm_process.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

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

}  // namespace
