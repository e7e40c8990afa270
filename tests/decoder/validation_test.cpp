// Configuration and input validation of the reference decoder: clear std::invalid_argument, never garbage.
#include "decoder_test_support.hpp"
#include "trm/fixed_decoder.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <string>

namespace trm {
namespace {

using test::decoder_config;
using test::error_of;

TEST(DecoderConfig, RejectsInvalidSettings) {
  EncoderConfig link;
  DecoderConfig config = decoder_config(link);
  EXPECT_NO_THROW(config.validate());

  DecoderConfig negative_s = config;
  negative_s.sensitivity = -1.0;
  EXPECT_NE(error_of([&] { negative_s.validate(); }).find("sensitivity"), std::string::npos);
  DecoderConfig nan_s = config;
  nan_s.sensitivity = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(nan_s.validate(), std::invalid_argument);
  DecoderConfig infinite_s = config;
  infinite_s.sensitivity = std::numeric_limits<double>::infinity();
  EXPECT_NO_THROW(infinite_s.validate());

  DecoderConfig bits = config;
  bits.output_bits = 12;
  EXPECT_NE(error_of([&] { bits.validate(); }).find("output_bits"), std::string::npos);
  DecoderConfig bad_link = config;
  bad_link.link.reduction = 0.0;
  EXPECT_THROW(bad_link.validate(), std::invalid_argument);
  DecoderConfig bad_gamma = config;
  bad_gamma.panel.oled.gamma[1] = 0.0;
  EXPECT_THROW(bad_gamma.validate(), std::invalid_argument);
  DecoderConfig bad_lcd = decoder_config(link, "lcd");
  bad_lcd.panel.lcd.p2 = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(bad_lcd.validate(), std::invalid_argument);
  EXPECT_THROW(ReferenceDecoder{bad_lcd}, std::invalid_argument);
}

TEST(DecoderInput, RejectsFramesThatDoNotMatchTheConfiguration) {
  EncoderConfig link;
  const TrmEncoder encoder(link);
  const cv::Mat image = test::random_image(11, 9, 41);
  ReferenceDecoder decoder(decoder_config(link));

  // A reduced frame whose size is not reduced_size(full): 11 x 9 at r = 1/2 must be 6 x 5.
  LinkFrame reduced = encoder.encode(image, 1);
  ASSERT_EQ(reduced.codes.size(), cv::Size(6, 5));
  LinkFrame wrong_size = reduced;
  wrong_size.codes = cv::Mat::zeros(4, 5, CV_16UC3);
  wrong_size.meta.width = 5;
  wrong_size.meta.height = 4;
  EXPECT_NE(error_of([&] { decoder.decode(wrong_size); }).find("must be 6x5"), std::string::npos);
  // A full frame labelled with another full size.
  LinkFrame full = encoder.encode(image, 0);
  LinkFrame wrong_full = full;
  wrong_full.meta.full_width = 12;
  EXPECT_THROW(decoder.decode(wrong_full), std::invalid_argument);
  // Metadata that disagrees with the codes.
  LinkFrame wrong_meta = full;
  wrong_meta.meta.width = 10;
  EXPECT_THROW(decoder.decode(wrong_meta), std::invalid_argument);

  LinkFrame ten_bit = full;
  ten_bit.meta.bits = 10;
  EXPECT_NE(error_of([&] { decoder.decode(ten_bit); }).find("link bits"), std::string::npos);
  LinkFrame other_transfer = full;
  other_transfer.meta.transfer = Transfer::Gamma22;
  EXPECT_NE(error_of([&] { decoder.decode(other_transfer); }).find("transfer"), std::string::npos);
  LinkFrame out_of_range = full;
  out_of_range.codes = full.codes.clone();
  out_of_range.codes.at<cv::Vec3w>(2, 3)[1] = 256;
  EXPECT_NE(error_of([&] { decoder.decode(out_of_range); }).find("exceeds"), std::string::npos);
  LinkFrame wrong_type = full;
  full.codes.convertTo(wrong_type.codes, CV_8UC3);
  EXPECT_THROW(decoder.decode(wrong_type), std::invalid_argument);
  LinkFrame negative_eye = full;
  negative_eye.meta.eye = -1;
  EXPECT_THROW(decoder.decode(negative_eye), std::invalid_argument);

  // After all the rejections the decoder still works.
  EXPECT_NO_THROW(decoder.decode(full));
  EXPECT_TRUE(decoder.decode(reduced).stats.residual_applied);
}

TEST(DecoderOutput, ReportsTheFullSizeAndKeepsTheParity) {
  EncoderConfig link;
  const TrmEncoder encoder(link);
  ReferenceDecoder decoder(decoder_config(link));
  const cv::Mat image = test::random_image(97, 61, 42);
  const DecodedFrame f = decoder.decode(encoder.encode(image, 0));
  const DecodedFrame r = decoder.decode(encoder.encode(image, 1));
  for (const DecodedFrame* d : {&f, &r}) {
    EXPECT_EQ(d->meta.width, 97);
    EXPECT_EQ(d->meta.height, 61);
    EXPECT_EQ(d->drive_codes.type(), CV_16UC3);
    EXPECT_EQ(d->drive.type(), CV_64FC3);
    EXPECT_EQ(d->emitted_linear.size(), cv::Size(97, 61));
  }
  EXPECT_EQ(r.meta.parity, Parity::Reduced);
  EXPECT_EQ(r.stages->at(Stage::Codes).size(), cv::Size(49, 31));  // 97 * 0.5 rounds half up to 49
}

TEST(DecoderOutput, StagesAreOnlyRecordedOnRequest) {
  EncoderConfig link;
  DecoderConfig config = decoder_config(link);
  config.record_stages = false;
  ReferenceDecoder decoder(config);
  EXPECT_FALSE(decoder.decode(TrmEncoder(link).encode(test::random_image(5, 5, 43), 0)).stages.has_value());
}

}  // namespace
}  // namespace trm

namespace trm {
namespace {

// Every decoder behind the one interface, by name: the same view decodes through each to the same size, and the
// fixed-point ones report their stage events (the streaming one its hardware too).
TEST(DecoderFactory, EveryNameMakesItsDecoderAndUnknownNamesAreListed) {
  FixedDecoderConfig config;
  config.decoder = test::decoder_config(EncoderConfig{});
  const TrmEncoder encoder(config.decoder.link);
  const LinkFrame full = encoder.encode(test::random_image(11, 9, 5), 0);
  ASSERT_EQ(decoder_names(), (std::vector<std::string>{"reference", "fixed", "fixed-frame"}));
  for (const std::string& name : decoder_names()) {
    const std::unique_ptr<HeadsetDecoder> decoder = make_decoder(name, config);
    EXPECT_EQ(decoder->name(), name);
    const DecodedFrame decoded = decoder->decode(full);
    EXPECT_EQ(decoded.drive_codes.size(), cv::Size(11, 9)) << name;
    EXPECT_EQ(decoder->stage_counts() != nullptr, name != "reference") << name;
    FixedStreamingReport hardware;
    EXPECT_EQ(decoder->hardware_report(cv::Size(11, 9), hardware), name == "fixed") << name;
  }
  const std::string message = test::error_of([&] { (void)make_decoder("fixed-point", config); });
  EXPECT_NE(message.find("'fixed-point'"), std::string::npos) << message;
  EXPECT_NE(message.find("reference, fixed, fixed-frame"), std::string::npos) << message;
}

}  // namespace
}  // namespace trm
