// The double reference's run-time choices and its planes: without the report planes it gives the same codes and
// statistics, and the planes it fills again for later views are never ones a caller still holds.
#include "decoder_test_support.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <string>
#include <vector>

namespace trm {
namespace {

cv::Mat moving_frame(std::int64_t t) { return test::half_moving_frame(96, 40, 20261207, t); }

// A stream with a lost first view (black), full and reduced views, a full and a reduced view with lost lines
// (concealed), and a lost view in the middle (held).
DecodedFrame decode_step(ReferenceDecoder& decoder, const TrmEncoder& encoder, std::int64_t t) {
  const LinkFrame view = encoder.encode(moving_frame(t), t);
  if (t == 0 || t == 5) return decoder.decode_lost(view.meta);
  if (t == 3 || t == 6) {
    std::vector<std::uint8_t> intact(static_cast<std::size_t>(view.codes.rows), 1);
    for (std::size_t y = 2; y < 6 && y < intact.size(); ++y) intact[y] = 0;
    return decoder.decode(view, intact);
  }
  return decoder.decode(view);
}

TEST(ReferenceDecoder, WithoutReportPlanesGivesTheSameCodesAndStatistics) {
  struct Case {
    const char* panel;
    LcdHistory history;
    int bits;  // the link's and the drive codes'
  };
  for (const Case& c : {Case{"vive", LcdHistory::Wanted, 8}, Case{"vive", LcdHistory::Wanted, 10},
                        Case{"lcd", LcdHistory::Wanted, 8}, Case{"lcd", LcdHistory::Contributed, 8}}) {
    const char* panel = c.panel;
    for (const bool record : {false, true}) {
      EncoderConfig link;
      link.bits = c.bits;
      DecoderConfig with_planes = test::decoder_config(link, panel);
      with_planes.output_bits = c.bits;
      with_planes.record_stages = record;
      with_planes.lcd_history = c.history;
      DecoderConfig codes_only = with_planes;
      codes_only.report_planes = false;
      ReferenceDecoder planes_decoder(with_planes);
      ReferenceDecoder codes_decoder(codes_only);
      const TrmEncoder encoder(link);
      for (std::int64_t t = 0; t < 9; ++t) {
        const std::string where = std::string(panel) + ", " + std::to_string(c.bits) + " bits" +
                                  (c.history == LcdHistory::Contributed ? ", contributed" : "") +
                                  (record ? ", stages" : "") + ", t = " + std::to_string(t);
        const DecodedFrame a = decode_step(planes_decoder, encoder, t);
        const DecodedFrame b = decode_step(codes_decoder, encoder, t);
        ASSERT_FALSE(a.wanted_linear.empty()) << where;
        ASSERT_FALSE(a.drive.empty()) << where;
        ASSERT_FALSE(a.emitted_linear.empty()) << where;
        EXPECT_TRUE(b.wanted_linear.empty()) << where;
        EXPECT_TRUE(b.drive.empty()) << where;
        EXPECT_TRUE(b.emitted_linear.empty()) << where;
        ASSERT_EQ(b.drive_codes.size(), a.drive_codes.size()) << where;
        EXPECT_EQ(cv::norm(a.drive_codes, b.drive_codes, cv::NORM_INF), 0.0) << where;
        test::expect_same_stats(a.stats, b.stats, where);
        ASSERT_EQ(a.stages.has_value(), b.stages.has_value()) << where;
        if (a.stages) {
          for (std::size_t s = 0; s < a.stages->planes.size(); ++s) {
            const cv::Mat& pa = a.stages->planes[s];
            const cv::Mat& pb = b.stages->planes[s];
            ASSERT_EQ(pa.empty(), pb.empty()) << where << ", stage " << s;
            if (!pa.empty()) {
              EXPECT_EQ(cv::norm(pa, pb, cv::NORM_INF), 0.0) << where << ", stage " << s;
            }
          }
        }
      }
    }
  }
}

TEST(ReferenceDecoder, FillsAgainOnlyThePlanesNoCallerHolds) {
  for (const char* panel : {"vive", "lcd"}) {
    EncoderConfig link;
    DecoderConfig config = test::decoder_config(link, panel);
    config.record_stages = false;
    const TrmEncoder encoder(link);
    // Every view kept, with its stage record and a held view (lost at t = 5): each keeps the samples it had when it
    // was returned.
    {
      DecoderConfig recording = config;
      recording.record_stages = true;
      ReferenceDecoder decoder(recording);
      std::vector<DecodedFrame> kept;
      std::vector<std::vector<cv::Mat>> copies;
      const auto planes_of = [](const DecodedFrame& d) {
        std::vector<cv::Mat> planes{d.wanted_linear, d.drive, d.drive_codes, d.emitted_linear};
        if (d.stages) planes.insert(planes.end(), d.stages->planes.begin(), d.stages->planes.end());
        return planes;
      };
      for (std::int64_t t = 1; t < 9; ++t) {
        const LinkFrame view = encoder.encode(moving_frame(t), t);
        kept.push_back(t == 5 ? decoder.decode_lost(view.meta) : decoder.decode(view));
        std::vector<cv::Mat> copy;
        for (const cv::Mat& m : planes_of(kept.back())) copy.push_back(m.clone());
        copies.push_back(copy);
      }
      for (std::size_t i = 0; i < kept.size(); ++i) {
        const std::vector<cv::Mat> now = planes_of(kept[i]);
        ASSERT_EQ(now.size(), copies[i].size());
        for (std::size_t p = 0; p < now.size(); ++p) {
          if (now[p].empty()) continue;
          EXPECT_EQ(cv::norm(now[p], copies[i][p], cv::NORM_INF), 0.0)
              << panel << ", view " << i << ", plane " << p;
        }
      }
    }
    // No view kept: after the first views, every output lands in memory an earlier view used (no new planes), and
    // the codes are those of a decoder whose views were all kept.
    {
      ReferenceDecoder reusing(config);
      ReferenceDecoder keeping(config);
      std::vector<DecodedFrame> kept;
      std::set<const uchar*> seen;
      int fresh_after_warm_up = 0;
      for (std::int64_t t = 1; t < 13; ++t) {
        const LinkFrame view = encoder.encode(moving_frame(t), t);
        const DecodedFrame d = reusing.decode(view);
        kept.push_back(keeping.decode(view));
        EXPECT_EQ(cv::norm(d.drive_codes, kept.back().drive_codes, cv::NORM_INF), 0.0) << panel << ", t = " << t;
        for (const cv::Mat* m : {&d.wanted_linear, &d.drive, &d.drive_codes, &d.emitted_linear}) {
          if (seen.insert(m->data).second && t > 4) ++fresh_after_warm_up;
        }
      }
      EXPECT_EQ(fresh_after_warm_up, 0) << panel;
    }
  }
}

}  // namespace
}  // namespace trm
