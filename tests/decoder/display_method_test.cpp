// The display methods (decoder/src/methods): the registry, and the baselines of the paper's Table 1 against their
// analytic answers (pixels per pair, mean light over a pair, repeated frames, NCSFI's pair average).
#include "decoder_test_support.hpp"
#include "trm/display_method.hpp"
#include "trm/reference_decoder.hpp"
#include "trm/scene.hpp"
#include "trm/transfer.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm {
namespace {

struct Slot {
  FrameMeta meta;
  bool sent = false;
  std::int64_t pixels_sent = 0;
  std::int64_t pixels_rendered = 0;
  DecodedFrame shown;
  cv::Mat linear;  // the scene at t
};

struct RunSpec {
  std::string method = "trm";
  std::string scene = "static";
  cv::Size size{41, 27};  // odd on both axes: fields and reduced sizes that do not divide evenly
  int frames = 6;
  bool stereo = false;
  int phase = 0;
  std::string panel = "vive";
  std::string impl = "reference";
};

// Drives a method's two sides directly, every slot in (t, eye) order, no link.
std::vector<Slot> run_method(const RunSpec& spec) {
  const MethodChoice choice = find_display_method(spec.method);
  MethodSetup setup;
  setup.decoder.decoder.link.stereo = spec.stereo;
  setup.decoder.decoder.link.phase = spec.phase;
  setup.decoder.decoder.panel = parse_panel(spec.panel);
  setup.impl = spec.impl;
  setup.option = choice.option;
  const auto sender = choice.method->make_sender(setup);
  const auto display = choice.method->make_display(setup);
  SceneParams params;
  params.width = spec.size.width;
  params.height = spec.size.height;
  const auto scene = make_scene(spec.scene, params);
  std::vector<Slot> slots;
  for (int t = 0; t < spec.frames; ++t) {
    const cv::Mat linear = scene->linear_frame(t);
    for (int eye = 0; eye < (spec.stereo ? 2 : 1); ++eye) {
      Slot slot;
      slot.linear = linear;
      if (sender->sends(t, eye)) {
        Transmission sent = sender->send(linear, t, eye);
        slot.sent = true;
        slot.meta = sent.frame.meta;
        slot.pixels_sent = static_cast<std::int64_t>(sent.frame.codes.total());
        slot.pixels_rendered = sent.pixels_rendered;
        EXPECT_EQ(sent.frame.meta.width, sent.frame.codes.cols);
        EXPECT_EQ(sent.frame.meta.height, sent.frame.codes.rows);
        const FrameMeta scheduled = sender->view_meta(t, eye, spec.size);
        EXPECT_EQ(scheduled.width, sent.frame.meta.width) << spec.method << " t=" << t;
        EXPECT_EQ(scheduled.height, sent.frame.meta.height) << spec.method << " t=" << t;
        EXPECT_EQ(scheduled.parity, sent.frame.meta.parity) << spec.method << " t=" << t;
        slot.shown = display->show(sent.frame, {});
      } else {
        slot.meta = unsent_slot(t, eye, spec.size, setup.decoder.decoder.link);
        slot.shown = display->show_unsent(slot.meta);
      }
      EXPECT_EQ(slot.shown.drive_codes.size(), spec.size) << spec.method;
      slots.push_back(std::move(slot));
    }
  }
  return slots;
}

// Pixels sent (or rendered) per pair of one eye's slots, over the whole run, as a fraction of full rate.
double fraction_of_full(const std::vector<Slot>& slots, bool rendered) {
  double sum = 0.0, full = 0.0;
  for (const Slot& s : slots) {
    sum += static_cast<double>(rendered ? s.pixels_rendered : s.pixels_sent);
    full += static_cast<double>(s.meta.full_width) * s.meta.full_height;
  }
  return sum / full;
}

// The mean of the emitted light of slots a and b (OLED: the Talbot-Plateau average the eye sees).
cv::Mat pair_mean(const Slot& a, const Slot& b) { return 0.5 * (a.shown.emitted_linear + b.shown.emitted_linear); }

TEST(DisplayMethods, RegistryListsTheTableOneBaselinesAndRefusesUnknownNamesAndOptions) {
  std::vector<std::string> names;
  for (const DisplayMethod& m : display_methods()) {
    names.push_back(m.name);
    EXPECT_FALSE(m.summary.empty()) << m.name;
    EXPECT_NE(m.make_sender, nullptr) << m.name;
    EXPECT_NE(m.make_display, nullptr) << m.name;
  }
  EXPECT_EQ(names, (std::vector<std::string>{"trm", "full", "half-rate", "interlace", "bfi", "ncsfi", "didyk", "kim",
                                             "kim-trm", "reprojection"}));
  EXPECT_EQ(find_display_method("interlace:double").option, "double");
  try {
    (void)find_display_method("quincunx");
    ADD_FAILURE() << "unknown method accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("available: trm, full, half-rate"), std::string::npos) << e.what();
  }
  EXPECT_THROW(check_display_method("bfi:fast", "reference"), std::invalid_argument);
  EXPECT_THROW(check_display_method("interlace:triple", "reference"), std::invalid_argument);
  EXPECT_THROW(check_display_method("trm:", "reference"), std::invalid_argument);
  // The plain-frame methods have no fixed-point decoder; TRM's family takes every decoder.
  EXPECT_THROW(check_display_method("full", "fixed"), std::invalid_argument);
  EXPECT_NO_THROW(check_display_method("ncsfi", "fixed"));
  EXPECT_NO_THROW(check_display_method("interlace:double", "reference"));
}

TEST(DisplayMethods, HalfRateInterlaceAndBfiSendExactlyHalfOfFullRate) {
  for (const bool stereo : {false, true}) {
    for (const int phase : {0, 1}) {
      for (const char* method : {"half-rate", "interlace", "bfi"}) {
        RunSpec spec;
        spec.method = method;
        spec.stereo = stereo;
        spec.phase = phase;
        spec.scene = "discs";
        const auto slots = run_method(spec);
        EXPECT_DOUBLE_EQ(fraction_of_full(slots, false), 0.5) << method << " stereo " << stereo << " phase " << phase;
        EXPECT_DOUBLE_EQ(fraction_of_full(slots, true), 0.5) << method << " stereo " << stereo << " phase " << phase;
      }
      RunSpec spec;
      spec.method = "full";
      spec.stereo = stereo;
      spec.phase = phase;
      EXPECT_DOUBLE_EQ(fraction_of_full(run_method(spec), false), 1.0);
    }
  }
}

TEST(DisplayMethods, TrmAndNcsfiSendTheSamePayloadButNcsfiRendersHalf) {
  RunSpec spec;
  spec.size = cv::Size(40, 30);  // r W and r H integers: (1 + r^2) / 2 exactly (DESIGN §6)
  spec.method = "trm";
  const auto trm_slots = run_method(spec);
  spec.method = "ncsfi";
  const auto ncsfi_slots = run_method(spec);
  EXPECT_DOUBLE_EQ(fraction_of_full(trm_slots, false), (1.0 + 0.25) / 2.0);
  EXPECT_DOUBLE_EQ(fraction_of_full(trm_slots, true), (1.0 + 0.25) / 2.0);
  EXPECT_DOUBLE_EQ(fraction_of_full(ncsfi_slots, false), (1.0 + 0.25) / 2.0);
  EXPECT_DOUBLE_EQ(fraction_of_full(ncsfi_slots, true), 0.5);
}

TEST(DisplayMethods, OnAStaticSceneBfiAndInterlaceEmitHalfOfFullOverAPair) {
  RunSpec spec;
  spec.method = "full";
  const auto full = run_method(spec);
  spec.method = "bfi";
  const auto bfi = run_method(spec);
  spec.method = "interlace";
  const auto interlace = run_method(spec);
  spec.method = "interlace:double";
  const auto doubled = run_method(spec);
  for (std::size_t t = 0; t + 1 < full.size(); t += 2) {
    const cv::Mat reference = pair_mean(full[t], full[t + 1]);
    // BFI: the rendered frame then black. Interlace: every pixel lit in one frame of the pair and black in the other.
    EXPECT_LE(cv::norm(pair_mean(bfi[t], bfi[t + 1]), 0.5 * reference, cv::NORM_INF), 1e-15) << "t=" << t;
    EXPECT_LE(cv::norm(pair_mean(interlace[t], interlace[t + 1]), 0.5 * reference, cv::NORM_INF), 1e-15) << "t=" << t;
    const cv::Scalar light = cv::mean(reference);
    EXPECT_GT(light[0] + light[1] + light[2], 0.05) << "a scene bright enough for the halving to show";
    // Line doubling keeps the peak luminance: its pair mean is full's mean light, not half of it, within the
    // scene's row-to-row variation.
    EXPECT_NEAR(cv::mean(pair_mean(doubled[t], doubled[t + 1]))[1], cv::mean(reference)[1], 0.02) << "t=" << t;
  }
  // Black rows really are black: the odd rows of an even-field frame emit nothing.
  const cv::Mat even_field = interlace[0].shown.emitted_linear;
  for (int y = 1; y < even_field.rows; y += 2) EXPECT_EQ(cv::norm(even_field.row(y), cv::NORM_INF), 0.0) << y;
}

TEST(DisplayMethods, HalfRateShowsEachRenderedFrameTwiceBitForBit) {
  for (const char* panel : {"vive", "lcd"}) {
    RunSpec spec;
    spec.method = "half-rate";
    spec.scene = "discs";  // moving: a repeat is not the scene's next frame
    spec.panel = panel;
    const auto slots = run_method(spec);
    for (std::size_t t = 0; t + 1 < slots.size(); t += 2) {
      ASSERT_TRUE(slots[t].sent && !slots[t + 1].sent);
      EXPECT_EQ(cv::norm(slots[t].shown.drive_codes, slots[t + 1].shown.drive_codes, cv::NORM_INF), 0.0) << panel << t;
    }
    // And the rendered frame is the scene at its own t, shown through the panel's held inverse.
    RunSpec full_spec = spec;
    full_spec.method = "full";
    const auto full = run_method(full_spec);
    EXPECT_EQ(cv::norm(slots[2].shown.drive_codes, full[2].shown.drive_codes, cv::NORM_INF), 0.0) << panel;
    EXPECT_GT(cv::norm(slots[3].shown.drive_codes, full[3].shown.drive_codes, cv::NORM_INF), 0.0) << panel;
  }
}

TEST(DisplayMethods, NcsfiPairAveragesItsFrameOnStaticContentAndAddsTheResidualWhereTrmKeepsItOut) {
  RunSpec spec;
  spec.method = "ncsfi";
  spec.scene = "static";
  const auto still = run_method(spec);
  spec.method = "full";
  const auto full = run_method(spec);
  // Static content: the sharpened + blurred pair averages to the frame, within the output quantisation (the drive
  // codes' step at the brightest level: d(v^gamma)/dv <= gamma at v = 1, half a code each way).
  const double code_step = 2.3 / 255.0;
  for (std::size_t t = 0; t + 1 < still.size(); t += 2) {
    EXPECT_LE(cv::norm(pair_mean(still[t], still[t + 1]), pair_mean(full[t], full[t + 1]), cv::NORM_INF), code_step)
        << "t=" << t;
  }
  // Moving content: TRM's motion test keeps the residual out (w < 1), NCSFI adds it whatever the motion (w = 1);
  // both send the same views' sizes, so the difference is the headset's rule and what the blurred frame shows.
  spec.scene = "discs";
  spec.method = "ncsfi";
  const auto moving_ncsfi = run_method(spec);
  spec.method = "trm";
  const auto moving_trm = run_method(spec);
  double trm_weight = 0.0, ncsfi_weight = 0.0;
  int reduced = 0;
  for (std::size_t t = 1; t < moving_trm.size(); t += 2) {
    ASSERT_EQ(moving_trm[t].meta.parity, Parity::Reduced);
    ASSERT_TRUE(moving_ncsfi[t].shown.stats.residual_applied);
    trm_weight += moving_trm[t].shown.stats.mean_motion_weight;
    ncsfi_weight += moving_ncsfi[t].shown.stats.mean_motion_weight;
    ++reduced;
  }
  EXPECT_DOUBLE_EQ(ncsfi_weight / reduced, 1.0);
  EXPECT_LT(trm_weight / reduced, 0.999);
  // NCSFI's blurred frame is of the frame before: its pair averages that frame, not the scene's motion over the pair.
  spec.method = "full";
  const auto moving_full = run_method(spec);
  const cv::Mat ncsfi_pair = pair_mean(moving_ncsfi[2], moving_ncsfi[3]);
  const cv::Mat held_pair = pair_mean(moving_full[2], moving_full[2]);
  const cv::Mat moving_pair = pair_mean(moving_full[2], moving_full[3]);
  EXPECT_LE(cv::norm(ncsfi_pair, held_pair, cv::NORM_INF), code_step);
  EXPECT_GT(cv::norm(ncsfi_pair, moving_pair, cv::NORM_INF), 10 * code_step);
}

TEST(DisplayMethods, TrmMethodIsTheTrmEncoderAndDecoderBitForBit) {
  RunSpec spec;
  spec.scene = "discs";
  spec.stereo = true;
  const auto slots = run_method(spec);
  DecoderConfig config;
  config.link.stereo = true;
  config.panel = parse_panel("vive");
  ReferenceDecoder decoder(config);
  TrmEncoder encoder(config.link);
  SceneParams params;
  params.width = spec.size.width;
  params.height = spec.size.height;
  const auto scene = make_scene("discs", params);
  std::size_t i = 0;
  for (int t = 0; t < spec.frames; ++t) {
    const cv::Mat linear = scene->linear_frame(t);
    for (int eye = 0; eye < 2; ++eye, ++i) {
      const DecodedFrame direct = decoder.decode(encoder.encode(linear, t, eye));
      EXPECT_EQ(cv::norm(direct.drive_codes, slots[i].shown.drive_codes, cv::NORM_INF), 0.0) << t << " " << eye;
      EXPECT_EQ(slots[i].pixels_rendered, slots[i].pixels_sent);
    }
  }
}

TEST(DisplayMethods, LostViewsHoldAndLostLinesAreConcealedInEveryMethod) {
  for (const DisplayMethod& m : display_methods()) {
    MethodSetup setup;
    const auto sender = m.make_sender(setup);
    const auto display = m.make_display(setup);
    SceneParams params;
    params.width = 24;
    params.height = 16;
    const auto scene = make_scene("discs", params);
    Transmission first = sender->send(scene->linear_frame(0), 0, 0);
    (void)display->show(first.frame, {});
    // Every line but the first lost: concealed, counted, and still a whole view.
    std::vector<std::uint8_t> intact(static_cast<std::size_t>(first.frame.codes.rows), 0);
    intact[0] = 1;
    int t = 1;
    while (!sender->sends(t, 0)) display->show_unsent(unsent_slot(t++, 0, cv::Size(24, 16), setup.decoder.decoder.link));
    Transmission next = sender->send(scene->linear_frame(t), t, 0);
    std::vector<std::uint8_t> next_intact(static_cast<std::size_t>(next.frame.codes.rows), 0);
    next_intact[0] = 1;
    const DecodedFrame concealed = display->show(next.frame, next_intact);
    EXPECT_EQ(concealed.stats.concealed_lines, next.frame.codes.rows - 1) << m.name;
    EXPECT_EQ(concealed.drive_codes.size(), cv::Size(24, 16)) << m.name;
    // A whole view lost: the panel holds what it showed.
    ++t;
    while (!sender->sends(t, 0)) display->show_unsent(unsent_slot(t++, 0, cv::Size(24, 16), setup.decoder.decoder.link));
    const DecodedFrame lost = display->show_lost(sender->view_meta(t, 0, cv::Size(24, 16)));
    EXPECT_TRUE(lost.stats.frame_lost) << m.name;
    EXPECT_EQ(cv::norm(lost.drive_codes, concealed.drive_codes, cv::NORM_INF), 0.0) << m.name;
  }
}

// DecoderConfig::report_planes = false is one setting for every method: the same codes and statistics in every slot
// (sent, unsent, lost, on both panels, with the TRM methods on both decoders), and no report plane.
TEST(DisplayMethods, WithoutReportPlanesEveryMethodShowsTheSameCodesAndStatistics) {
  const cv::Size size(24, 16);
  SceneParams params;
  params.width = size.width;
  params.height = size.height;
  const auto scene = make_scene("discs", params);
  for (const DisplayMethod& m : display_methods()) {
    for (const std::string panel : {"vive", "lcd"}) {
      for (const std::string impl : {"reference", "fixed"}) {
        if (impl == "fixed" && !m.fixed_point) continue;  // a plain-frame method has no fixed-point decoder
        std::array<std::vector<DecodedFrame>, 2> shown;  // [0]: with the planes, [1]: without
        for (const bool planes : {true, false}) {
          MethodSetup setup;
          setup.decoder.decoder.panel = parse_panel(panel);
          setup.decoder.decoder.report_planes = planes;
          setup.impl = impl;
          const auto sender = m.make_sender(setup);
          const auto display = m.make_display(setup);
          for (int t = 0; t < 7; ++t) {
            if (!sender->sends(t, 0)) {
              shown[planes ? 0 : 1].push_back(display->show_unsent(unsent_slot(t, 0, size, setup.decoder.decoder.link)));
            } else if (t == 4) {
              shown[planes ? 0 : 1].push_back(display->show_lost(sender->view_meta(t, 0, size)));
            } else {
              shown[planes ? 0 : 1].push_back(display->show(sender->send(scene->linear_frame(t), t, 0).frame, {}));
            }
          }
        }
        for (std::size_t t = 0; t < shown[0].size(); ++t) {
          const std::string where = m.name + " " + panel + " " + impl + " t=" + std::to_string(t);
          const DecodedFrame& with = shown[0][t];
          const DecodedFrame& without = shown[1][t];
          ASSERT_FALSE(with.drive_codes.empty()) << where;
          EXPECT_EQ(cv::norm(with.drive_codes, without.drive_codes, cv::NORM_INF), 0.0) << where;
          test::expect_same_stats(with.stats, without.stats, where);
          EXPECT_FALSE(with.emitted_linear.empty()) << where;
          EXPECT_TRUE(without.wanted_linear.empty() && without.drive.empty() && without.emitted_linear.empty()) << where;
        }
      }
    }
  }
}

TEST(DisplayMethods, AViewThatDoesNotMatchTheDisplayIsRefusedWithAClearMessage) {
  for (const char* name : {"full", "interlace"}) {
    MethodSetup setup;
    const MethodChoice choice = find_display_method(name);
    const auto display = choice.method->make_display(setup);
    LinkFrame frame;
    frame.meta.full_width = frame.meta.width = 8;
    frame.meta.full_height = frame.meta.height = 6;
    frame.codes = cv::Mat(6, 8, CV_16UC3, cv::Scalar::all(300));  // above 8 bits
    try {
      (void)display->show(frame, {});
      ADD_FAILURE() << name << " accepted codes above the link depth";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("exceeds 8 bits"), std::string::npos) << name << ": " << e.what();
    }
  }
}

}  // namespace
}  // namespace trm
