// Link presets, CVT-RB v2 timing, bandwidth accounting, frames.csv and the plot's bounded trace.
#include "trm/bandwidth.hpp"
#include "trm/presets.hpp"

#include "link_test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace trm::link {
namespace {

TEST(Presets, DataRatesAreTheSpecifiedOnes) {
  struct Expected { const char* name; double gbps; double tolerance; };
  for (const Expected e : {Expected{"dp1.2", 17.28, 1e-9}, Expected{"dp1.4", 25.92, 1e-9},
                           Expected{"dp2.1-uhbr10", 38.684, 1e-9}, Expected{"dp2.1-uhbr13.5", 52.2234, 1e-9},
                           Expected{"dp2.1-uhbr20", 77.37, 0.005}, Expected{"hdmi2.0", 14.4, 1e-9},
                           Expected{"hdmi2.1", 42.67, 0.005}, Expected{"usb3-gen1", 4.0, 1e-9},
                           Expected{"usb3-gen2", 10.0 * 128 / 132, 1e-9}, Expected{"wigig", 4.62 * 0.55, 1e-9}}) {
    const LinkPreset p = parse_link_preset(e.name);
    EXPECT_EQ(p.name, e.name);
    EXPECT_NEAR(p.data_gbps(), e.gbps, e.tolerance) << e.name;
  }
  EXPECT_NEAR(parse_link_preset("hdmi2.1").data_gbps(), 48.0 * 16 / 18, 1e-12);
  EXPECT_EQ(builtin_link_presets().size(), 10u);
  for (std::size_t i = 1; i < builtin_link_presets().size(); ++i)
    EXPECT_LE(builtin_link_presets()[i - 1].data_gbps(), builtin_link_presets()[i].data_gbps());
}

TEST(Presets, CustomAndWigigThroughput) {
  EXPECT_DOUBLE_EQ(parse_link_preset("custom:10:0.8").data_gbps(), 8.0);
  EXPECT_DOUBLE_EQ(parse_link_preset("custom:2.5:1").data_gbps(), 2.5);
  EXPECT_DOUBLE_EQ(parse_link_preset("wigig:3.2").data_gbps(), 3.2);
}

TEST(Presets, BadNamesAndNumbersGiveClearErrors) {
  auto message_of = [](const std::string& text) {
    try {
      parse_link_preset(text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message_of("dp9").find("unknown link preset 'dp9'"), std::string::npos);
  EXPECT_NE(message_of("dp9").find("dp2.1-uhbr20"), std::string::npos);  // lists the valid names
  EXPECT_NE(message_of("custom:0:0.8").find("rate must be > 0"), std::string::npos);
  EXPECT_NE(message_of("custom:-3:0.8").find("rate must be > 0"), std::string::npos);
  EXPECT_NE(message_of("custom:10:0").find("efficiency"), std::string::npos);
  EXPECT_NE(message_of("custom:10:1.5").find("efficiency"), std::string::npos);
  EXPECT_NE(message_of("custom:abc:1").find("not a number"), std::string::npos);
  EXPECT_NE(message_of("custom:10").find("custom:RATE_GBPS:EFFICIENCY"), std::string::npos);
  EXPECT_NE(message_of("custom:nan:1").find("not a number"), std::string::npos);
  EXPECT_NE(message_of("custom:10x:1").find("not a number"), std::string::npos);
  EXPECT_NE(message_of("wigig:0").find("> 0"), std::string::npos);
  EXPECT_NE(message_of("").find("unknown link preset"), std::string::npos);
}

TEST(Timing, CvtRbV2MatchesPublishedModes) {
  // VESA CVT-RB v2 1920x1080 @ 60 Hz: 2000 x 1111 total, 133.320 MHz.
  const VideoTiming fhd = cvt_rb_v2_timing(1920, 1080, 60.0);
  EXPECT_EQ(fhd.h_total, 2000);
  EXPECT_EQ(fhd.v_total, 1111);
  EXPECT_NEAR(fhd.pixel_clock_hz, 133.320e6, 1.0);
  // 3840x2160 @ 60 Hz: 3920 x 2222, 522.614 MHz.
  const VideoTiming uhd = cvt_rb_v2_timing(3840, 2160, 60.0);
  EXPECT_EQ(uhd.h_total, 3920);
  EXPECT_EQ(uhd.v_total, 2222);
  EXPECT_NEAR(uhd.pixel_clock_hz, 522.614e6, 1.0);
  // A tiny raster still gets the minimum 15 blanking lines.
  EXPECT_EQ(cvt_rb_v2_timing(8, 2, 60.0).v_total, 2 + 15);
  EXPECT_THROW(cvt_rb_v2_timing(0, 10, 60.0), std::invalid_argument);
  EXPECT_THROW(cvt_rb_v2_timing(10, 10, 0.0), std::invalid_argument);
  EXPECT_THROW(cvt_rb_v2_timing(10, 10, 3000.0), std::invalid_argument);  // 460 us blanking > 333 us frame
}

TEST(Bandwidth, UsageFitAndMinimumPreset) {
  LinkBudget budget{parse_link_preset("custom:1:1"), 100.0, std::nullopt};  // 1e7 bits per frame
  BandwidthMeter meter(budget);
  ViewBits small{8'000'000, 8'000'000, 1'000'000, 10};
  ViewBits large{10'000'000, 10'000'000, 1'000'000, 10};
  EXPECT_TRUE(meter.add(0, "F", small, 1).fits);
  const LinkFrameUsage& u = meter.add(1, "R", large, 1);
  EXPECT_FALSE(u.fits);
  EXPECT_NEAR(u.wire_seconds, 11e6 / 1e9, 1e-15);
  EXPECT_NEAR(u.utilisation, 1.1, 1e-12);
  const BandwidthSummary s = meter.summary();
  EXPECT_EQ(s.link_frames, 2);
  EXPECT_EQ(s.peak_wire_bits, 11'000'000u);
  EXPECT_DOUBLE_EQ(s.average_wire_bits, 10'000'000.0);
  EXPECT_EQ(s.frames_not_fitting, 1);
  EXPECT_FALSE(s.fits);
  EXPECT_NEAR(s.required_data_gbps, 1.1, 1e-12);
  ASSERT_TRUE(s.minimum_preset);
  EXPECT_EQ(s.minimum_preset->name, "wigig");  // 2.54 Gbit/s, the slowest built-in

  EXPECT_EQ(minimum_fitting_preset(400'000'000, 90.0, std::nullopt)->name, "dp2.1-uhbr10");  // 36 Gbit/s
  EXPECT_FALSE(minimum_fitting_preset(1'000'000'000, 90.0, std::nullopt));             // 90 Gbit/s: none
  EXPECT_THROW(BandwidthMeter(LinkBudget{parse_link_preset("dp1.2"), 0.0, std::nullopt}), std::invalid_argument);
}

TEST(Bandwidth, BlankingShortensTheTimeAvailable) {
  const VideoTiming timing = cvt_rb_v2_timing(2160, 1200, 90.0);
  LinkBudget with{parse_link_preset("dp1.2"), 90.0, timing}, without{parse_link_preset("dp1.2"), 90.0, std::nullopt};
  EXPECT_NEAR(with.available_seconds() / without.available_seconds(), timing.active_fraction(), 1e-15);
  EXPECT_LT(timing.active_fraction(), 0.95);
  EXPECT_GT(timing.active_fraction(), 0.85);
}

// The headline numbers: a 1080x1200-per-eye headset at 90 Hz, 8-bit, r = 1/2.
TEST(Bandwidth, HeadsetStereoTrmFlattensThePeakAndNeedsLessLink) {
  const PacketizerConfig config;
  auto bits_of = [&](std::int64_t t, int eye, bool stereo, double r) {
    FrameMeta m;
    m.index = t;
    m.eye = eye;
    const bool full = r == 1.0 || ((t + (stereo ? eye : 0)) % 2) == 0;
    m.parity = full ? Parity::Full : Parity::Reduced;
    m.full_width = 1080;
    m.full_height = 1200;
    m.width = full ? 1080 : test_support::reduced_size(1080, r);
    m.height = full ? 1200 : test_support::reduced_size(1200, r);
    return predict_raw_view_bits(m, config);
  };
  BandwidthMeter full_rate({parse_link_preset("dp1.2"), 90.0, std::nullopt});
  BandwidthMeter trm_mono({parse_link_preset("dp1.2"), 90.0, std::nullopt});
  BandwidthMeter trm_stereo({parse_link_preset("dp1.2"), 90.0, std::nullopt});
  for (std::int64_t t = 0; t < 4; ++t) {
    ViewBits f = bits_of(t, 0, true, 1.0);
    f += bits_of(t, 1, true, 1.0);
    full_rate.add(t, "FF", f, 2);
    trm_mono.add(t, t % 2 ? "R" : "F", bits_of(t, 0, false, 0.5), 1);
    ViewBits s = bits_of(t, 0, true, 0.5);
    s += bits_of(t, 1, true, 0.5);
    trm_stereo.add(t, t % 2 ? "RF" : "FR", s, 2);
  }
  const BandwidthSummary fs = full_rate.summary(), ms = trm_mono.summary(), ss = trm_stereo.summary();
  EXPECT_EQ(fs.peak_payload_bits, 2u * 1080 * 1200 * 24);             // 62.208 Mbit
  EXPECT_EQ(ss.peak_payload_bits, (1080u * 1200 + 540 * 600) * 24);   // 38.880 Mbit, every frame
  EXPECT_EQ(ms.peak_payload_bits, 1080u * 1200 * 24);                 // 31.104 Mbit on full frames
  EXPECT_DOUBLE_EQ(ss.average_payload_bits, static_cast<double>(ss.peak_payload_bits));  // flat
  EXPECT_DOUBLE_EQ(ms.average_payload_bits, (1080.0 * 1200 + 540 * 600) * 24 / 2);
  EXPECT_EQ(fs.minimum_preset->name, "usb3-gen2");   // 5.7 Gbit/s needed
  EXPECT_EQ(ss.minimum_preset->name, "usb3-gen1");   // 3.6 Gbit/s needed
  std::cout << "1080x1200x2 @ 90 Hz, 8 bit: full rate " << fs.peak_wire_bits << " wire bits/frame ("
            << fs.required_data_gbps << " Gbit/s), TRM r=1/2 stereo " << ss.peak_wire_bits << " ("
            << ss.required_data_gbps << " Gbit/s), TRM mono peak " << ms.peak_wire_bits << ", average "
            << ms.average_wire_bits << "\n";
}

TEST(Bandwidth, CsvIsWritten) {
  // A directory of its own: the capture and link tests write (and stage) their files in test_link_out meanwhile.
  const std::filesystem::path dir = std::filesystem::path(TRM_BINARY_DIR) / "test_link_out" / "bandwidth_csv";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  BandwidthMeter meter({parse_link_preset("custom:1:1"), 100.0, std::nullopt});
  const std::vector<LinkFrameUsage> frames = {meter.add(0, "F", ViewBits{100, 100, 20, 1}, 1),
                                              meter.add(1, "R", ViewBits{50, 50, 20, 1}, 1)};
  write_frames_csv(dir / "frames.csv", frames, 100.0, "trm");
  std::ifstream in(dir / "frames.csv");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str().substr(0, text.str().find('\n')),
            "link_frame,time_s,views,parities,pixel_bits,payload_bits,overhead_bits,wire_bits,packets,"
            "wire_time_s,available_time_s,utilisation,fits,method");
  EXPECT_NE(text.str().find("\n1,0.01,1,R,50,50,20,70,1,"), std::string::npos);
  EXPECT_NE(text.str().find(",1,trm\n"), std::string::npos) << "each row ends with its method";

  for (const auto& entry : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(entry.path().string().find(".partial-"), std::string::npos) << "staging file left: " << entry.path();
  EXPECT_THROW(write_frames_csv(dir / "no_such_dir" / "frames.csv", frames, 100.0, "trm"), std::runtime_error);
}

TEST(Bandwidth, PlotTraceStaysBoundedAndKeepsTheEnvelope) {
  PlotTrace trace("long run", 8);
  for (int i = 0; i < 100; ++i) trace.add(i == 37 ? 1000.0 : i == 50 ? std::nan("") : i);
  EXPECT_EQ(trace.count(), 100);
  EXPECT_EQ(trace.bucket_width(), 16);  // 8 buckets of 8 values held 64; 100 needs width 16
  ASSERT_EQ(trace.buckets().size(), 7u);
  EXPECT_EQ(trace.buckets().front().first, 0.0);
  EXPECT_EQ(trace.buckets().back().last, 99.0);
  EXPECT_EQ(trace.buckets()[2].max, 1000.0);  // values 32..47
  EXPECT_EQ(trace.buckets()[3].min, 48.0);    // the NaN is left out of min and max
  EXPECT_EQ(trace.buckets()[3].max, 63.0);

  PlotTrace short_trace("short", 8);
  for (double v : {100.0, 50.0, 100.0}) short_trace.add(v);
  EXPECT_EQ(short_trace.bucket_width(), 1);
  ASSERT_EQ(short_trace.buckets().size(), 3u);
  EXPECT_EQ(short_trace.buckets()[1].min, 50.0);
  EXPECT_THROW(PlotTrace("odd", 3), std::invalid_argument);
}

}  // namespace
}  // namespace trm::link
