// FixedStreamingDecoder's incremental form (begin_view, push_line, end_view): line by line it gives exactly the rows
// of the frame-at-a-time schedule, each row as soon as the line-buffer schedule has it (the latency the hardware
// report states), lost lines concealed as decode(frame, line_intact) conceals them, and misuse is refused without
// disturbing the view.
#include "fixed_decoder_test_support.hpp"

#include "trm/resample.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm {
namespace {

using test::encode_sequence;
using test::fixed_config;
using test::link_config;
using test::noise_images;
using test::scene_images;

// The message of the std::logic_error (a call out of order) `action` throws; empty when it throws nothing.
std::string order_error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const std::invalid_argument&) {
    return "an invalid argument instead";
  } catch (const std::logic_error& e) {
    return e.what();
  }
  return "";
}

// The input line after which each output row of a whole view is final, from the resampling operators alone (not the
// decoder's schedule): a full frame's row y needs input line y (E_t, for I_t) and reduced row i1(y) of d_t, whose
// vertical Gaussian taps end at the clamped last tap; a reduced frame's row y needs reduced input line i1(y).
std::vector<int> ready_after(const FrameMeta& meta, const EncoderConfig& link) {
  const int full_h = meta.full_height;
  const int reduced_h = reduced_size(full_h, link.reduction);
  std::vector<int> ready(static_cast<std::size_t>(full_h));
  for (int y = 0; y < full_h; ++y) {
    const int i1 = bilinear_tap(y, full_h, reduced_h).i1;
    if (meta.parity == Parity::Reduced) {
      ready[static_cast<std::size_t>(y)] = i1;
      continue;
    }
    // Reduced rows are produced in order, so row i1 waits for the latest last tap of rows 0 .. i1.
    int last_tap = 0;
    for (int k = 0; k <= i1; ++k) {
      const GaussianTaps taps = gaussian_taps(k, full_h, reduced_h, link.effective_sigma());
      last_tap = std::max(last_tap, std::min(taps.first_index + static_cast<int>(taps.weights.size()) - 1, full_h - 1));
    }
    ready[static_cast<std::size_t>(y)] = std::max(y, last_tap);
  }
  return ready;
}

std::span<const std::uint16_t> line_of(const cv::Mat& codes, int y) {
  return {codes.ptr<std::uint16_t>(y), static_cast<std::size_t>(3 * codes.cols)};
}

// Pushes every line of each frame, checking after every push which rows are ready (against ready_after for whole
// views) and that each row's drive codes are those of the frame-at-a-time decoder; the ended view must equal that
// decoder's output bit for bit. mask_of(n) gives the n-th view's line mask (empty: whole).
void expect_line_by_line(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config,
                         const std::string& what,
                         const std::function<std::vector<std::uint8_t>(std::size_t, int)>& mask_of = nullptr) {
  FixedFrameDecoder frame_decoder(config);
  FixedStreamingDecoder streaming(config);
  const EncoderConfig& link = config.decoder.link;
  for (std::size_t n = 0; n < frames.size(); ++n) {
    const LinkFrame& frame = frames[n];
    const std::vector<std::uint8_t> mask = mask_of ? mask_of(n, frame.codes.rows) : std::vector<std::uint8_t>();
    const std::string where = what + " view " + std::to_string(n);
    const DecodedFrame expected = mask.empty() ? frame_decoder.decode(frame) : frame_decoder.decode(frame, mask);
    const std::vector<int> ready = ready_after(frame.meta, link);
    streaming.begin_view(frame.meta);
    int shown = 0;
    for (int y_in = 0; y_in < frame.codes.rows; ++y_in) {
      const bool intact = mask.empty() || mask[static_cast<std::size_t>(y_in)] != 0;
      const int rows = streaming.push_line(line_of(frame.codes, y_in), intact);
      ASSERT_EQ(rows, streaming.rows_ready()) << where;
      ASSERT_GE(rows, shown) << where << " line " << y_in;
      if (mask.empty()) {
        const int oracle =
            static_cast<int>(std::count_if(ready.begin(), ready.end(), [&](int r) { return r <= y_in; }));
        ASSERT_EQ(rows, oracle) << where << ": rows ready after input line " << y_in;
      }
      for (; shown < rows; ++shown) {
        const std::span<const std::uint16_t> row = streaming.drive_row(shown);
        const std::uint16_t* want = expected.drive_codes.ptr<std::uint16_t>(shown);
        ASSERT_TRUE(std::equal(row.begin(), row.end(), want, want + 3 * expected.drive_codes.cols))
            << where << ": drive codes of row " << shown << " after input line " << y_in;
      }
    }
    const DecodedFrame got = streaming.end_view();
    test::expect_identical_outputs(expected, frame_decoder.last_counts(), got, streaming.last_counts(), where);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

TEST(FixedStreamingLines, RowsMatchTheFrameDecoderAndArriveWithTheScheduledLatency) {
  for (const char* panel : {"vive", "lcd"}) {
    for (double r : {1.0, 0.5, 0.4}) {
      const EncoderConfig link = link_config(r, 0, true);
      expect_line_by_line(encode_sequence(scene_images("discs", 37, 23, 4), link), fixed_config(link, panel),
                          std::string(panel) + " discs r=" + std::to_string(r));
    }
  }
  const EncoderConfig deep = link_config(0.5, 1, false, 10, ResampleSpace::Linear);
  expect_line_by_line(encode_sequence(noise_images(40, 30, 4, 11), deep), fixed_config(deep, "rift", 10),
                      "10-bit linear noise");
}

// The report's latencies are the largest of the per-row delays: no row waits longer, and some row waits that long.
TEST(FixedStreamingLines, ReportedLatencyIsTheLongestRowDelay) {
  for (double r : {0.75, 0.5, 0.4, 0.25}) {
    const EncoderConfig link = link_config(r);
    const FixedStreamingDecoder decoder(fixed_config(link));
    for (const cv::Size full : {cv::Size(64, 48), cv::Size(37, 101), cv::Size(2160, 1200)}) {
      const FixedStreamingReport report = decoder.report(full);
      FrameMeta meta;
      meta.full_width = full.width;
      meta.full_height = full.height;
      meta.parity = Parity::Full;
      const std::vector<int> full_ready = ready_after(meta, link);
      int full_delay = 0;
      for (int y = 0; y < full.height; ++y) {
        full_delay = std::max(full_delay, full_ready[static_cast<std::size_t>(y)] - y);
      }
      EXPECT_EQ(report.full_latency_lines, full_delay) << "r=" << r << " " << full;
      meta.parity = Parity::Reduced;
      const std::vector<int> reduced_ready = ready_after(meta, link);
      int reduced_delay = 0;
      for (int y = 0; y < full.height; ++y) {
        const int i0 = bilinear_tap(y, full.height, report.reduced.height).i0;
        reduced_delay = std::max(reduced_delay, reduced_ready[static_cast<std::size_t>(y)] - i0);
      }
      EXPECT_EQ(report.reduced_latency_lines, reduced_delay) << "r=" << r << " " << full;
    }
  }
}

// Lost lines pushed as lost: the same bits as the frame decoder's decode(frame, line_intact), including views whose
// top lines are lost (their rows wait for the first intact line) and views with no intact line (rows at the end).
TEST(FixedStreamingLines, LostLinesAreConcealedAsInDecodeWithAMask) {
  const auto mask_of = [](std::size_t n, int lines) {
    std::vector<std::uint8_t> mask(static_cast<std::size_t>(lines), 1);
    switch (n % 5) {
      case 0: break;
      case 1: for (int y = 0; y < lines / 2; ++y) mask[static_cast<std::size_t>(y)] = 0; break;
      case 2: for (int y = 1; y < lines; y += 3) mask[static_cast<std::size_t>(y)] = 0; break;
      case 3: mask.assign(mask.size(), 0); break;
      default: mask.front() = 0; mask.back() = 0; break;
    }
    return mask;
  };
  for (const char* panel : {"vive", "lcd"}) {
    const EncoderConfig link = link_config(0.5, 0, true);
    expect_line_by_line(encode_sequence(noise_images(33, 21, 10, 70), link), fixed_config(link, panel),
                        std::string(panel) + " faulty", mask_of);
  }
}

TEST(FixedStreamingLines, MisuseIsRefusedAndLeavesTheViewIntact) {
  const EncoderConfig link = link_config(0.5);
  const std::vector<LinkFrame> frames = encode_sequence(noise_images(16, 10, 1, 3), link);
  const LinkFrame& frame = frames[0];
  FixedStreamingDecoder decoder(fixed_config(link));
  const DecodedFrame expected = FixedFrameDecoder(fixed_config(link)).decode(frame);
  EXPECT_NE(order_error_of([&] { decoder.push_line(line_of(frame.codes, 0)); }).find("without an open view"),
            std::string::npos);
  EXPECT_NE(order_error_of([&] { decoder.end_view(); }).find("without an open view"), std::string::npos);
  FrameMeta wrong = frame.meta;
  wrong.width = 9;
  EXPECT_NE(test::error_of([&] { decoder.begin_view(wrong); }).find("must be 16x10"), std::string::npos);
  decoder.begin_view(frame.meta);
  EXPECT_NE(order_error_of([&] { decoder.begin_view(frame.meta); }).find("is still open"), std::string::npos);
  EXPECT_NE(order_error_of([&] { decoder.decode(frame); }).find("is still open"), std::string::npos);
  EXPECT_NE(test::error_of([&] { decoder.push_line(line_of(frame.codes, 0).first(47)); }).find("has 47 samples"),
            std::string::npos);
  std::vector<std::uint16_t> too_high(line_of(frame.codes, 0).begin(), line_of(frame.codes, 0).end());
  too_high[5] = 256;
  EXPECT_NE(test::error_of([&] { decoder.push_line(too_high); }).find("code 256 exceeds the 8-bit range"),
            std::string::npos);
  EXPECT_EQ(decoder.lines_pushed(), 0);  // nothing was taken
  for (int y = 0; y < 5; ++y) decoder.push_line(line_of(frame.codes, y));
  EXPECT_NE(order_error_of([&] { decoder.end_view(); }).find("after 5 of its 10 lines"), std::string::npos);
  EXPECT_THROW(decoder.drive_row(decoder.rows_ready()), std::out_of_range);
  for (int y = 5; y < 10; ++y) decoder.push_line(line_of(frame.codes, y));
  EXPECT_NE(order_error_of([&] { decoder.push_line(line_of(frame.codes, 0)); }).find("after all 10 lines"),
            std::string::npos);
  const DecodedFrame got = decoder.end_view();
  EXPECT_TRUE(test::identical(got.drive_codes, expected.drive_codes));
  EXPECT_FALSE(decoder.view_open());
}

}  // namespace
}  // namespace trm
