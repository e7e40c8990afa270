// The C API (trm/trm_c.h): a sequence decoded line by line through it equals the C++ decoders bit for bit (OLED and
// LCD, 8- and 10-bit, odd sizes, stereo, lost lines and lost views; from C99 as well), and every misuse returns its
// status with a message that says what was wrong, leaving the handle usable.
#include "fixed_decoder_test_support.hpp"
#include "trm_c_c99.h"

#include "trm/decoder_json.hpp"
#include "trm/trm_c.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace trm {
namespace {

using test::encode_sequence;
using test::fixed_config;
using test::link_config;
using test::noise_images;
using test::scene_images;

struct HandleDeleter {
  void operator()(trm_decoder* d) const { trm_decoder_destroy(d); }
};
using Handle = std::unique_ptr<trm_decoder, HandleDeleter>;

Handle create_from(const FixedDecoderConfig& config) {
  trm_decoder* d = nullptr;
  const std::string json = fixed_decoder_json(config).dump();
  EXPECT_EQ(trm_decoder_create_json(json.c_str(), &d), TRM_OK) << trm_last_error();
  return Handle(d);
}

bool contains(const char* text, const std::string& part) { return std::string(text).find(part) != std::string::npos; }

// One view through the C API, popping after every push; rows must come in raster order. Returns the drive codes.
cv::Mat decode_through_c(trm_decoder* d, const LinkFrame& frame, const std::vector<std::uint8_t>& mask = {}) {
  const FrameMeta& m = frame.meta;
  cv::Mat drive(m.full_height, m.full_width, CV_16UC3, cv::Scalar::all(0xffff));
  const int kind = m.parity == Parity::Full ? TRM_FRAME_FULL : TRM_FRAME_REDUCED;
  EXPECT_EQ(trm_decoder_begin_view(d, m.full_width, m.full_height, kind, m.eye, m.index), TRM_OK)
      << trm_decoder_last_error(d);
  trm_view_shape shape{};
  EXPECT_EQ(trm_decoder_view_shape(d, &shape), TRM_OK);
  EXPECT_EQ(shape.input_lines, frame.codes.rows);
  EXPECT_EQ(shape.input_samples, 3 * frame.codes.cols);
  EXPECT_EQ(shape.output_samples, 3 * m.full_width);
  int next = 0;
  std::vector<std::uint16_t> spare(static_cast<std::size_t>(3 * drive.cols));  // where a row too many would land
  const auto pop_all = [&] {
    int32_t row = -1;
    size_t samples = 0;
    for (;;) {
      const trm_status s = trm_decoder_pop_line(
          d, &row, next < drive.rows ? drive.ptr<std::uint16_t>(next) : spare.data(), spare.size(), &samples);
      if (s == TRM_NO_LINE) return;
      ASSERT_EQ(s, TRM_OK) << trm_decoder_last_error(d);
      ASSERT_EQ(row, next);
      ASSERT_EQ(samples, static_cast<size_t>(3 * drive.cols));
      ++next;
    }
  };
  for (int y = 0; y < frame.codes.rows; ++y) {
    const bool intact = mask.empty() || mask[static_cast<std::size_t>(y)] != 0;
    EXPECT_EQ(trm_decoder_push_line(d, frame.codes.ptr<std::uint16_t>(y), 3 * frame.codes.cols, intact ? 1 : 0),
              TRM_OK)
        << trm_decoder_last_error(d);
    pop_all();
  }
  EXPECT_EQ(trm_decoder_end_view(d), TRM_OK) << trm_decoder_last_error(d);
  pop_all();
  EXPECT_EQ(next, drive.rows);
  return drive;
}

void expect_counts_equal(const trm_stage_counts& c, const FixedStageCounts& e, const std::string& where) {
  EXPECT_EQ(c.beta_clipped, e.beta_clipped) << where;
  EXPECT_EQ(c.residual_saturated, e.residual_saturated) << where;
  EXPECT_EQ(c.residual_rounded, e.residual_rounded) << where;
  EXPECT_EQ(c.alpha_clipped, e.alpha_clipped) << where;
  EXPECT_EQ(c.weight_underflow, e.weight_underflow) << where;
  EXPECT_EQ(c.lcd_unreachable, e.lcd_unreachable) << where;
  EXPECT_EQ(c.motion_test_lines_skipped, e.motion_test_lines_skipped) << where;
  EXPECT_EQ(c.residual_read_lines_skipped, e.residual_read_lines_skipped) << where;
  EXPECT_EQ(c.residual_write_lines_skipped, e.residual_write_lines_skipped) << where;
}

// The frame-at-a-time decoder (the other schedule) as the oracle, view by view, with its stage counters.
void expect_c_matches(const std::vector<LinkFrame>& frames, const FixedDecoderConfig& config, const std::string& what,
                      const std::function<std::vector<std::uint8_t>(std::size_t, int)>& mask_of = nullptr) {
  FixedFrameDecoder oracle(config);
  const Handle d = create_from(config);
  ASSERT_TRUE(d);
  for (std::size_t n = 0; n < frames.size(); ++n) {
    const std::vector<std::uint8_t> mask = mask_of ? mask_of(n, frames[n].codes.rows) : std::vector<std::uint8_t>();
    const std::string where = what + " view " + std::to_string(n);
    const LinkFrame sent = mask.empty() ? frames[n] : test::damaged(frames[n], mask);
    const DecodedFrame expected = oracle.decode(sent, mask);
    const cv::Mat got = decode_through_c(d.get(), sent, mask);
    ASSERT_TRUE(test::identical(got, expected.drive_codes)) << where;
    trm_stage_counts counts{};
    ASSERT_EQ(trm_decoder_stage_counts(d.get(), &counts), TRM_OK);
    expect_counts_equal(counts, oracle.last_counts(), where);
  }
}

TEST(CApi, LineByLineEqualsTheCppDecoder) {
  for (const char* panel : {"vive", "lcd"}) {
    for (const char* scene : {"discs", "panorama", "jitter"}) {
      const EncoderConfig link = link_config(0.5, 0, true);
      expect_c_matches(encode_sequence(scene_images(scene, 48, 32, 4), link), fixed_config(link, panel),
                       std::string(panel) + " " + scene);
    }
  }
  // 10-bit link and drive, odd sizes and reductions, the linear resample space, saturating clipping.
  const EncoderConfig deep = link_config(0.4, 1, false, 10);
  expect_c_matches(encode_sequence(noise_images(37, 23, 4, 5), deep), fixed_config(deep, "lcd", 10), "lcd 10-bit");
  expect_c_matches(encode_sequence(noise_images(31, 19, 4, 9), deep), fixed_config(deep, "rift", 10), "oled 10-bit");
  const EncoderConfig linear = link_config(0.75, 0, true, 8, ResampleSpace::Linear);
  expect_c_matches(encode_sequence(scene_images("text", 29, 17, 4), linear), fixed_config(linear, "vive"),
                   "linear space");
}

TEST(CApi, LostLinesAndLostViewsEqualTheCppDecoder) {
  const auto mask_of = [](std::size_t n, int lines) {
    std::vector<std::uint8_t> mask(static_cast<std::size_t>(lines), 1);
    switch (n % 4) {
      case 0: break;
      case 1: for (int y = 0; y < lines / 3; ++y) mask[static_cast<std::size_t>(y)] = 0; break;
      case 2: for (int y = 2; y < lines; y += 4) mask[static_cast<std::size_t>(y)] = 0; break;
      default: mask.assign(mask.size(), 0); break;  // nothing intact: the previous output again
    }
    return mask;
  };
  for (const char* panel : {"vive", "lcd"}) {
    const EncoderConfig link = link_config(0.5, 0, true);
    expect_c_matches(encode_sequence(noise_images(35, 21, 8, 31), link), fixed_config(link, panel),
                     std::string(panel) + " faulty", mask_of);
  }
  // A view that never arrived: the eye's previous output, as decode_lost.
  const EncoderConfig link = link_config(0.5);
  const std::vector<LinkFrame> frames = encode_sequence(noise_images(20, 12, 3, 1), link);
  FixedStreamingDecoder oracle(fixed_config(link));
  const Handle d = create_from(fixed_config(link));
  ASSERT_TRUE(test::identical(decode_through_c(d.get(), frames[0]), oracle.decode(frames[0]).drive_codes));
  const FrameMeta& lost = frames[1].meta;
  ASSERT_EQ(trm_decoder_lost_view(d.get(), lost.full_width, lost.full_height, TRM_FRAME_REDUCED, 0, lost.index), TRM_OK)
      << trm_decoder_last_error(d.get());
  const DecodedFrame held = oracle.decode_lost(lost);
  int32_t ready = 0;
  ASSERT_EQ(trm_decoder_lines_ready(d.get(), &ready), TRM_OK);
  EXPECT_EQ(ready, lost.full_height);
  std::vector<std::uint16_t> row(3 * 20);
  for (int y = 0; y < ready; ++y) {
    int32_t index = -1;
    ASSERT_EQ(trm_decoder_pop_line(d.get(), &index, row.data(), row.size(), nullptr), TRM_OK);
    EXPECT_EQ(index, y);
    EXPECT_TRUE(std::equal(row.begin(), row.end(), held.drive_codes.ptr<std::uint16_t>(y)));
  }
  ASSERT_TRUE(test::identical(decode_through_c(d.get(), frames[2]), oracle.decode(frames[2]).drive_codes));
}

TEST(CApi, WorksFromC99) {
  const EncoderConfig link = FixedDecoderConfig().decoder.link;  // the C side starts from trm_config_defaults
  const std::vector<LinkFrame> frames = encode_sequence(scene_images("discs", 33, 19, 3), link);
  std::vector<int32_t> kinds, eyes;
  std::vector<int64_t> indices;
  std::vector<const std::uint16_t*> codes;
  std::vector<std::vector<std::uint8_t>> masks = {{}, {}, std::vector<std::uint8_t>(frames[2].codes.rows, 1)};
  masks[2][3] = 0;
  masks[2][4] = 0;
  std::vector<LinkFrame> sent;
  for (std::size_t n = 0; n < frames.size(); ++n) {
    sent.push_back(masks[n].empty() ? frames[n] : test::damaged(frames[n], masks[n]));
    sent.back().codes = sent.back().codes.clone();  // continuous rows: the C side reads lines back to back
  }
  std::vector<const std::uint8_t*> intact;
  for (std::size_t n = 0; n < frames.size(); ++n) {
    kinds.push_back(frames[n].meta.parity == Parity::Full ? TRM_FRAME_FULL : TRM_FRAME_REDUCED);
    eyes.push_back(frames[n].meta.eye);
    indices.push_back(frames[n].meta.index);
    codes.push_back(sent[n].codes.ptr<std::uint16_t>(0));
    intact.push_back(masks[n].empty() ? nullptr : masks[n].data());
  }
  std::vector<std::uint16_t> drive(frames.size() * 3 * 33 * 19);
  char message[512];
  // Default configuration (trm_config_defaults) from C, against the C++ decoder's defaults with this link.
  ASSERT_EQ(c99_decode_views(nullptr, 33, 19, 3, kinds.data(), eyes.data(), indices.data(), codes.data(),
                             intact.data(), drive.data(), message, sizeof message),
            0)
      << message;
  FixedFrameDecoder oracle{FixedDecoderConfig()};
  for (std::size_t n = 0; n < frames.size(); ++n) {
    const DecodedFrame expected = masks[n].empty() ? oracle.decode(sent[n]) : oracle.decode(sent[n], masks[n]);
    const cv::Mat got(19, 33, CV_16UC3, drive.data() + n * 3 * 33 * 19);
    EXPECT_TRUE(test::identical(got, expected.drive_codes)) << "view " << n;
  }
  // From JSON, and its failure path from C.
  const std::string json = fixed_decoder_json(fixed_config(link, "lcd")).dump();
  EXPECT_EQ(c99_decode_views(json.c_str(), 33, 19, 3, kinds.data(), eyes.data(), indices.data(), codes.data(),
                             intact.data(), drive.data(), message, sizeof message),
            0)
      << message;
  EXPECT_EQ(c99_decode_views("{\"decoder\": 1}", 33, 19, 3, kinds.data(), eyes.data(), indices.data(), codes.data(),
                             intact.data(), drive.data(), message, sizeof message),
            TRM_ERROR_INVALID_CONFIG);
  EXPECT_NE(std::string(message), "");
}

TEST(CApi, CreatesFromTheStructAsFromTheEquivalentJson) {
  trm_config c;
  trm_config_defaults(&c);
  c.reduction = 0.4;
  c.link_bits = 10;
  c.transfer = TRM_TRANSFER_GAMMA22;
  c.resample_space = TRM_RESAMPLE_LINEAR;
  c.sensitivity = INFINITY;
  c.panel = "lcd";
  c.output_bits = 10;
  c.lcd_history = TRM_LCD_HISTORY_CONTRIBUTED;
  c.skip_unneeded = 0;
  trm_decoder* raw = nullptr;
  ASSERT_EQ(trm_decoder_create(&c, &raw), TRM_OK) << trm_last_error();
  const Handle d(raw);
  FixedDecoderConfig expected = fixed_config(link_config(0.4, 0, false, 10, ResampleSpace::Linear), "lcd", 10);
  expected.decoder.link.transfer = Transfer::Gamma22;
  expected.decoder.sensitivity = std::numeric_limits<double>::infinity();
  expected.decoder.lcd_history = LcdHistory::Contributed;
  expected.skip_unneeded = false;
  const char* json = nullptr;
  ASSERT_EQ(trm_decoder_config_json(d.get(), &json), TRM_OK);
  EXPECT_EQ(nlohmann::json::parse(json), nlohmann::json::parse(fixed_decoder_json(expected).dump()));
  // The defaults are the C++ decoder's.
  trm_config_defaults(&c);
  ASSERT_EQ(trm_decoder_create(&c, &raw), TRM_OK);
  const Handle defaults(raw);
  ASSERT_EQ(trm_decoder_config_json(defaults.get(), &json), TRM_OK);
  EXPECT_EQ(nlohmann::json::parse(json), nlohmann::json::parse(fixed_decoder_json(FixedDecoderConfig()).dump()));
}

TEST(CApi, ReportIsTheHwReportDocument) {
  const FixedDecoderConfig config = fixed_config(link_config(0.5), "lcd");
  const Handle d = create_from(config);
  const char* json = nullptr;
  ASSERT_EQ(trm_decoder_report_json(d.get(), 2160, 1200, &json), TRM_OK) << trm_decoder_last_error(d.get());
  const nlohmann::json report = nlohmann::json::parse(json);
  const FixedStreamingReport expected = FixedStreamingDecoder(config).report(cv::Size(2160, 1200));
  EXPECT_EQ(report["parameters"]["size"], nlohmann::json::parse("[2160, 1200]"));
  EXPECT_EQ(report["hardware"]["full_frame_latency_lines"], expected.full_latency_lines);
  EXPECT_EQ(report["hardware"]["reduced_frame_latency_lines"], expected.reduced_latency_lines);
  EXPECT_EQ(report["hardware"]["buffers"].size(), expected.buffers.size());
  EXPECT_EQ(report["hardware"]["reduced_size"], nlohmann::json::parse("[1080, 600]"));
  // A hw-report document is also a configuration: the same decoder again.
  trm_decoder* again = nullptr;
  ASSERT_EQ(trm_decoder_create_json(json, &again), TRM_OK) << trm_last_error();
  const Handle twin(again);
  const char* config_json = nullptr;
  ASSERT_EQ(trm_decoder_config_json(twin.get(), &config_json), TRM_OK);
  EXPECT_EQ(nlohmann::json::parse(config_json), report["parameters"]["decoder"]);
  EXPECT_EQ(trm_decoder_report_json(d.get(), 0, 1200, &json), TRM_ERROR_INVALID_VIEW);
  EXPECT_TRUE(contains(trm_decoder_last_error(d.get()), "view 0x1200")) << trm_decoder_last_error(d.get());
}

TEST(CApi, BadConfigurationsAreRefusedWithAMessage) {
  trm_decoder* d = reinterpret_cast<trm_decoder*>(&d);  // must be reset to null on failure
  EXPECT_EQ(trm_decoder_create_json("{", &d), TRM_ERROR_INVALID_CONFIG);
  EXPECT_EQ(d, nullptr);
  EXPECT_TRUE(contains(trm_last_error(), "parse error")) << trm_last_error();
  EXPECT_EQ(trm_decoder_create_json("[1, 2]", &d), TRM_ERROR_INVALID_CONFIG);
  EXPECT_NE(std::string(trm_last_error()), "");
  nlohmann::json json = fixed_decoder_json(FixedDecoderConfig());
  json["decoder"]["output_bits"] = 9;
  EXPECT_EQ(trm_decoder_create_json(json.dump().c_str(), &d), TRM_ERROR_INVALID_CONFIG);
  EXPECT_TRUE(contains(trm_last_error(), "output")) << trm_last_error();
  json = fixed_decoder_json(FixedDecoderConfig());
  json["formats"].erase("linear_frac_bits");
  EXPECT_EQ(trm_decoder_create_json(json.dump().c_str(), &d), TRM_ERROR_INVALID_CONFIG);
  EXPECT_TRUE(contains(trm_last_error(), "linear_frac_bits")) << trm_last_error();
  json = fixed_decoder_json(FixedDecoderConfig());
  json["formats"]["linear_frac_bits"] = 16;  // cannot tell the darkest drive codes apart
  EXPECT_EQ(trm_decoder_create_json(json.dump().c_str(), &d), TRM_ERROR_INVALID_CONFIG);
  EXPECT_NE(std::string(trm_last_error()), "");
  EXPECT_EQ(trm_decoder_create_json(nullptr, &d), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(trm_decoder_create_json("{}", nullptr), TRM_ERROR_NULL_ARGUMENT);
  trm_config c;
  trm_config_defaults(&c);
  c.link_bits = 9;
  EXPECT_EQ(trm_decoder_create(&c, &d), TRM_ERROR_INVALID_CONFIG);
  EXPECT_TRUE(contains(trm_last_error(), "bits")) << trm_last_error();
  trm_config_defaults(&c);
  c.panel = "plasma";
  EXPECT_EQ(trm_decoder_create(&c, &d), TRM_ERROR_INVALID_CONFIG);
  EXPECT_TRUE(contains(trm_last_error(), "plasma")) << trm_last_error();
  trm_config_defaults(&c);
  c.transfer = 7;
  EXPECT_EQ(trm_decoder_create(&c, &d), TRM_ERROR_INVALID_CONFIG);
  EXPECT_TRUE(contains(trm_last_error(), "transfer 7")) << trm_last_error();
  trm_config_defaults(&c);
  c.reduction = std::nan("");
  EXPECT_EQ(trm_decoder_create(&c, &d), TRM_ERROR_INVALID_CONFIG);
  EXPECT_EQ(trm_decoder_create(nullptr, &d), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(d, nullptr);
  trm_decoder_destroy(nullptr);  // allowed
}

TEST(CApi, NullHandleAndNullPointersAreRefused) {
  int32_t row = 0;
  std::uint16_t sample = 0;
  trm_view_shape shape{};
  trm_stage_counts counts{};
  const char* json = nullptr;
  EXPECT_EQ(trm_decoder_begin_view(nullptr, 16, 8, TRM_FRAME_FULL, 0, 0), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_TRUE(contains(trm_last_error(), "trm_decoder_begin_view: null handle")) << trm_last_error();
  EXPECT_EQ(trm_decoder_push_line(nullptr, &sample, 1, 1), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_TRUE(contains(trm_decoder_last_error(nullptr), "trm_decoder_push_line: null handle"));
  EXPECT_EQ(trm_decoder_pop_line(nullptr, &row, &sample, 1, nullptr), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(trm_decoder_end_view(nullptr), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(trm_decoder_lost_view(nullptr, 16, 8, TRM_FRAME_FULL, 0, 0), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(trm_decoder_view_shape(nullptr, &shape), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(trm_decoder_lines_ready(nullptr, &row), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(trm_decoder_stage_counts(nullptr, &counts), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(trm_decoder_report_json(nullptr, 16, 8, &json), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(trm_decoder_config_json(nullptr, &json), TRM_ERROR_NULL_ARGUMENT);
  const Handle d = create_from(FixedDecoderConfig());
  EXPECT_EQ(trm_decoder_view_shape(d.get(), nullptr), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_TRUE(contains(trm_decoder_last_error(d.get()), "shape is null"));
  EXPECT_EQ(trm_decoder_stage_counts(d.get(), nullptr), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(trm_decoder_report_json(d.get(), 16, 8, nullptr), TRM_ERROR_NULL_ARGUMENT);
  ASSERT_EQ(trm_decoder_begin_view(d.get(), 16, 8, TRM_FRAME_FULL, 0, 0), TRM_OK);
  EXPECT_EQ(trm_decoder_push_line(d.get(), nullptr, 48, 1), TRM_ERROR_NULL_ARGUMENT);
  EXPECT_TRUE(contains(trm_decoder_last_error(d.get()), "codes of an intact line is null"));
  EXPECT_EQ(trm_decoder_push_line(d.get(), nullptr, 0, 0), TRM_OK);  // a lost line needs no codes
  EXPECT_EQ(trm_decoder_pop_line(d.get(), nullptr, &sample, 1, nullptr), TRM_ERROR_NULL_ARGUMENT);
}

// Every out-of-order or malformed call: its status, a message naming the problem, and the view going on unharmed
// (the decoded view still equals the C++ decoder's).
TEST(CApi, MisuseGivesItsStatusAndLeavesTheHandleUsable) {
  const EncoderConfig link = link_config(0.5);
  const std::vector<LinkFrame> frames = encode_sequence(noise_images(16, 40, 2, 8), link);
  FixedStreamingDecoder oracle(fixed_config(link));
  const DecodedFrame expected0 = oracle.decode(frames[0]);
  const DecodedFrame expected1 = oracle.decode(frames[1]);
  const Handle handle = create_from(fixed_config(link));
  trm_decoder* d = handle.get();
  const LinkFrame& f = frames[0];
  const auto line = [&](int y) { return f.codes.ptr<std::uint16_t>(y); };
  const auto last_error = [&] { return std::string(trm_decoder_last_error(d)); };

  EXPECT_EQ(trm_decoder_push_line(d, line(0), 48, 1), TRM_ERROR_NO_VIEW);
  EXPECT_NE(last_error().find("without an open view"), std::string::npos) << last_error();
  EXPECT_EQ(trm_decoder_end_view(d), TRM_ERROR_NO_VIEW);
  trm_view_shape shape{};
  EXPECT_EQ(trm_decoder_view_shape(d, &shape), TRM_ERROR_NO_VIEW);

  EXPECT_EQ(trm_decoder_begin_view(d, 16, 40, 2, 0, 0), TRM_ERROR_INVALID_VIEW);
  EXPECT_NE(last_error().find("frame kind 2"), std::string::npos) << last_error();
  EXPECT_EQ(trm_decoder_begin_view(d, 0, 10, TRM_FRAME_FULL, 0, 0), TRM_ERROR_INVALID_VIEW);
  EXPECT_NE(last_error().find("size"), std::string::npos) << last_error();
  EXPECT_EQ(trm_decoder_begin_view(d, 16, 40, TRM_FRAME_FULL, -1, 0), TRM_ERROR_INVALID_VIEW);
  EXPECT_EQ(trm_decoder_begin_view(d, 16, 40, TRM_FRAME_FULL, 0, -3), TRM_ERROR_INVALID_VIEW);

  ASSERT_EQ(trm_decoder_begin_view(d, 16, 40, TRM_FRAME_FULL, 0, 0), TRM_OK) << last_error();
  EXPECT_EQ(last_error(), "");  // cleared by the successful call
  EXPECT_EQ(trm_decoder_begin_view(d, 16, 40, TRM_FRAME_FULL, 0, 0), TRM_ERROR_VIEW_OPEN);
  EXPECT_NE(last_error().find("still open"), std::string::npos) << last_error();
  EXPECT_EQ(trm_decoder_lost_view(d, 16, 40, TRM_FRAME_FULL, 0, 0), TRM_ERROR_VIEW_OPEN);
  EXPECT_EQ(trm_decoder_push_line(d, line(0), 47, 1), TRM_ERROR_LINE_LENGTH);
  EXPECT_NE(last_error().find("47 samples but the view's input lines have 48"), std::string::npos) << last_error();
  std::vector<std::uint16_t> bad(line(0), line(0) + 48);
  bad[7] = 300;
  EXPECT_EQ(trm_decoder_push_line(d, bad.data(), 48, 1), TRM_ERROR_INVALID_CODE);
  EXPECT_NE(last_error().find("code 300 exceeds the 8-bit range"), std::string::npos) << last_error();
  for (int y = 0; y < 12; ++y) ASSERT_EQ(trm_decoder_push_line(d, line(y), 48, 1), TRM_OK) << last_error();
  EXPECT_EQ(trm_decoder_end_view(d), TRM_ERROR_VIEW_INCOMPLETE);
  EXPECT_NE(last_error().find("only 12 of the view's 40 lines"), std::string::npos) << last_error();
  int32_t ready = 0;
  ASSERT_EQ(trm_decoder_lines_ready(d, &ready), TRM_OK);
  ASSERT_GT(ready, 0);
  std::vector<std::uint16_t> small(47);
  int32_t row = -1;
  size_t samples = 0;
  EXPECT_EQ(trm_decoder_pop_line(d, &row, small.data(), small.size(), &samples), TRM_ERROR_BUFFER_TOO_SMALL);
  EXPECT_EQ(samples, 48u);  // what it needs
  EXPECT_NE(last_error().find("row 0 has 48 samples but the buffer holds 47"), std::string::npos) << last_error();
  for (int y = 12; y < 40; ++y) ASSERT_EQ(trm_decoder_push_line(d, line(y), 48, 1), TRM_OK) << last_error();
  EXPECT_EQ(trm_decoder_push_line(d, line(0), 48, 1), TRM_ERROR_TOO_MANY_LINES);
  EXPECT_NE(last_error().find("already has all its 40 lines"), std::string::npos) << last_error();
  ASSERT_EQ(trm_decoder_end_view(d), TRM_OK) << last_error();
  EXPECT_EQ(trm_decoder_push_line(d, line(0), 48, 1), TRM_ERROR_NO_VIEW);
  EXPECT_NE(last_error().find("after the end of the view"), std::string::npos) << last_error();
  EXPECT_EQ(trm_decoder_end_view(d), TRM_ERROR_NO_VIEW);
  EXPECT_NE(last_error().find("already ended"), std::string::npos) << last_error();
  // Every row, row 0 included (it stayed queued), equal to the C++ decoder's.
  std::vector<std::uint16_t> drive(48);
  for (int y = 0; y < 40; ++y) {
    ASSERT_EQ(trm_decoder_pop_line(d, &row, drive.data(), drive.size(), nullptr), TRM_OK) << last_error();
    EXPECT_EQ(row, y);
    EXPECT_TRUE(std::equal(drive.begin(), drive.end(), expected0.drive_codes.ptr<std::uint16_t>(y))) << "row " << y;
  }
  EXPECT_EQ(trm_decoder_pop_line(d, &row, drive.data(), drive.size(), nullptr), TRM_NO_LINE);
  // The next view pairs with it as if nothing had gone wrong.
  EXPECT_TRUE(test::identical(decode_through_c(d, frames[1]), expected1.drive_codes));
}

}  // namespace
}  // namespace trm
