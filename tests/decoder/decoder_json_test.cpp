// One writer and one reader of the decoder configurations.
#include "trm/decoder_json.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace trm {
namespace {

FixedDecoderConfig unusual_config() {
  FixedDecoderConfig config;
  config.decoder.link.reduction = 0.25;
  config.decoder.link.bits = 10;
  config.decoder.link.stereo = true;
  config.decoder.sensitivity = 3.5;
  config.decoder.panel = parse_panel("lcd:-0.05,0.1,0.5,0.01,2.4");
  config.decoder.output_bits = 10;
  config.decoder.lcd_history = LcdHistory::Contributed;
  config.linear_frac_bits = 26;
  config.exp_entries = 1025;
  config.residual = fx::RuntimeFormat{2, 20, true, fx::Quant::RndConv, fx::Overflow::Sat};
  config.skip_unneeded = false;
  return config;
}

void expect_same(const FixedDecoderConfig& a, const FixedDecoderConfig& b) {
  EXPECT_EQ(a.decoder.link.reduction, b.decoder.link.reduction);
  EXPECT_EQ(a.decoder.link.effective_sigma(), b.decoder.link.effective_sigma());
  EXPECT_EQ(a.decoder.link.bits, b.decoder.link.bits);
  EXPECT_EQ(a.decoder.link.stereo, b.decoder.link.stereo);
  EXPECT_EQ(a.decoder.sensitivity, b.decoder.sensitivity);
  EXPECT_TRUE(a.decoder.panel == b.decoder.panel);
  EXPECT_EQ(a.decoder.output_bits, b.decoder.output_bits);
  EXPECT_EQ(a.decoder.lcd_history, b.decoder.lcd_history);
  EXPECT_EQ(a.linear_frac_bits, b.linear_frac_bits);
  EXPECT_EQ(a.exp_entries, b.exp_entries);
  EXPECT_EQ(a.lcd_segments_per_octave, b.lcd_segments_per_octave);
  EXPECT_EQ(a.residual, b.residual);
  EXPECT_EQ(a.skip_unneeded, b.skip_unneeded);
}

TEST(DecoderJson, FixedConfigurationRoundTrips) {
  for (const FixedDecoderConfig& config : {FixedDecoderConfig{}, unusual_config()}) {
    const nlohmann::ordered_json written = fixed_decoder_json(config);
    const FixedDecoderConfig read = fixed_decoder_config_from_json(nlohmann::json::parse(written.dump()));
    expect_same(config, read);
    EXPECT_EQ(fixed_decoder_json(read), written);  // and writes the same text again
  }
}

TEST(DecoderJson, InfiniteSensitivityIsWrittenAsInf) {
  DecoderConfig config;
  config.sensitivity = std::numeric_limits<double>::infinity();
  const nlohmann::ordered_json j = decoder_json(config);
  EXPECT_EQ(j["sensitivity"], "inf");
  EXPECT_TRUE(std::isinf(decoder_config_from_json(nlohmann::json::parse(j.dump())).sensitivity));
}

TEST(DecoderJson, MalformedConfigurationsAreRefusedNamingTheField) {
  const nlohmann::json good = nlohmann::json::parse(fixed_decoder_json(FixedDecoderConfig{}).dump());
  const auto refused = [](const nlohmann::json& j, const std::string& needle) {
    try {
      (void)fixed_decoder_config_from_json(j);
      ADD_FAILURE() << "accepted: " << j.dump();
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  nlohmann::json j = good;
  j["formats"].erase("exp_entries");
  refused(j, "exp_entries");
  j = good;
  j["formats"]["linear_frac_bits"] = 20.5;
  refused(j, "linear_frac_bits");
  j = good;
  j["residual"]["quant"] = "Nearest";
  refused(j, "Nearest");
  j = good;
  j["decoder"]["lcd_history"] = "remembered";
  refused(j, "lcd_history");
  j = good;
  j["decoder"]["sensitivity"] = "fast";
  refused(j, "sensitivity");
  j = good;
  j["decoder"]["encoder"]["bits"] = 9;
  refused(j, "encoder");
  j = good;
  j["decoder"]["panel"]["kind"] = "crt";
  refused(j, "panel");
  j = good;
  j["decoder"]["output_bits"] = 12;  // a rule of the decoder, not of JSON
  refused(j, "output");
  j = good;
  j["formats"]["linear_frac_bits"] = 8;  // the fixed-point validation's own rule
  refused(j, "decoder configuration");
  refused(nlohmann::json::array(), "decoder");
}

}  // namespace
}  // namespace trm
