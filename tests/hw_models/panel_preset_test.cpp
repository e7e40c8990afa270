// `--panel lcd:FILE.json`: an LCD preset file read through the one panel parser.
#include <gtest/gtest.h>

#include "trm/panel.hpp"
#include "trm/panel_light.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>
#include <unistd.h>

namespace trm {
namespace {

std::filesystem::path preset_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("trm_panel_preset_" + std::to_string(::getpid()) + "_" + name);
}

std::filesystem::path write_file(const std::string& name, const std::string& text) {
  const std::filesystem::path path = preset_path(name);
  std::ofstream(path) << text;
  return path;
}

std::string rejection(const std::string& spec) {
  try {
    parse_panel(spec);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(PanelPreset, LcdFileRoundTripsEveryParameter) {
  Panel panel = parse_panel("lcd:-0.07,0.15,0.49,0.004,2.35");
  panel.name = "calibrated";
  nlohmann::json json = panel;
  const std::filesystem::path path = write_file("ok.json", json.dump(2));
  const Panel read = parse_panel("lcd:" + path.string());
  EXPECT_EQ(read, panel);
  EXPECT_EQ(read.lcd.p4, 0.004);
  std::filesystem::remove(path);
}

TEST(PanelPreset, BadFilesAreRejectedWithTheFileAndTheReason) {
  EXPECT_NE(rejection("lcd:/nonexistent/dir/p.json").find("cannot open the preset file"), std::string::npos);
  const std::filesystem::path garbage = write_file("garbage.json", "{ not json");
  EXPECT_NE(rejection("lcd:" + garbage.string()).find("is not JSON"), std::string::npos);
  nlohmann::json oled = parse_panel("vive");
  const std::filesystem::path oled_file = write_file("oled.json", oled.dump());
  EXPECT_NE(rejection("lcd:" + oled_file.string()).find("is not an LCD panel"), std::string::npos);
  // A merge that falls with the drive is no panel, from a file as from the command line.
  const std::filesystem::path falling =
      write_file("falling.json", R"({"kind": "lcd", "name": "x", "p1": 0, "p2": 0, "p3": -0.5, "p4": 1, "gamma": 2.2})");
  const std::string message = rejection("lcd:" + falling.string());
  EXPECT_NE(message.find("panel JSON"), std::string::npos) << message;
  const std::filesystem::path missing = write_file("missing.json", R"({"kind": "lcd", "name": "x", "p1": 0})");
  EXPECT_NE(rejection("lcd:" + missing.string()).find("missing \"p2\""), std::string::npos);
  // What is not a small regular file is refused before it is read (a directory failed the stream part-way).
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "trm_preset_dir.json";
  std::filesystem::create_directories(dir);
  EXPECT_NE(rejection("lcd:" + dir.string()).find("is not a file"), std::string::npos);
  std::filesystem::remove(dir);
  EXPECT_NE(rejection(std::string("lcd:.\0\0aP.json", 15)).find("invalid panel"), std::string::npos);  // a NUL
  EXPECT_NE(rejection("lcd:/dev/null.json").find("cannot open"), std::string::npos);
  for (const auto& path : {garbage, oled_file, falling, missing}) std::filesystem::remove(path);
}

TEST(PanelPreset, SecondOrderCrystalIsSelectedByThePresetAndValidated) {
  // Without the field the JSON is what it always was; with it, it round-trips and the eye model's light uses it.
  const Panel plain = parse_panel("lcd");
  EXPECT_FALSE(nlohmann::json(plain).contains("lc_second_order"));
  EXPECT_FALSE(panel_light(plain, 90.0).lc_second_order().has_value());
  Panel panel = plain;
  panel.lcd.lc_second_order = LcSecondOrderParams{0.0012, 1.4};
  const std::filesystem::path path = write_file("second_order.json", nlohmann::json(panel).dump(2));
  const Panel read = parse_panel("lcd:" + path.string());
  EXPECT_EQ(read, panel);
  EXPECT_NE(read, plain);
  const PanelLight light = panel_light(read, 90.0);
  ASSERT_TRUE(light.lc_second_order().has_value());
  EXPECT_EQ(light.lc_second_order()->params(), (LcSecondOrderParams{0.0012, 1.4}));
  EXPECT_FALSE(light.lc_response().has_value());
  std::filesystem::remove(path);

  const std::string head = R"({"kind": "lcd", "name": "x", "p1": -0.1, "p2": 0.2, "p3": 0.5, "p4": 0, "gamma": 2.2, )";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"("lc_second_order": {"tau_s": 0.002, "damping_ratio": 0.5}})", "must be >= 1"},
      {R"("lc_second_order": {"tau_s": 0, "damping_ratio": 1}})", "'tau_s'"},
      {R"("lc_second_order": {"tau_s": -1e-3, "damping_ratio": 1}})", "'tau_s'"},
      {R"("lc_second_order": {"tau_s": 0.002}})", "missing \"damping_ratio\""},
      {R"("lc_second_order": {"tau_s": "2ms", "damping_ratio": 1}})", "\"tau_s\" must be a number"},
      {R"("lc_second_order": {"tau_s": 0.002, "damping_ratio": 1, "mass": 3}})", "unknown field \"mass\""},
      {R"("lc_second_order": 0.002})", "must be an object"},
  };
  for (const auto& [tail, needle] : bad) {
    const std::filesystem::path file = write_file("bad_second_order.json", head + tail);
    const std::string message = rejection("lcd:" + file.string());
    EXPECT_NE(message.find(needle), std::string::npos) << tail << ": " << message;
    EXPECT_NE(message.find("panel JSON"), std::string::npos) << message;
    std::filesystem::remove(file);
  }
}

TEST(PanelPreset, OverdriveIsSelectedByThePresetAndValidated) {
  const Panel plain = parse_panel("lcd");
  EXPECT_FALSE(nlohmann::json(plain).contains("overdrive"));  // the JSON of a preset without it is unchanged
  EXPECT_FALSE(panel_light(plain, 90.0).config().overdrive);
  for (const bool second_order : {false, true}) {
    Panel panel = plain;
    panel.lcd.overdrive = true;
    if (second_order) panel.lcd.lc_second_order = LcSecondOrderParams{0.002, 1.0};
    const std::filesystem::path path = write_file("overdrive.json", nlohmann::json(panel).dump(2));
    const Panel read = parse_panel("lcd:" + path.string());
    EXPECT_EQ(read, panel);
    EXPECT_NE(read, plain);
    const PanelLight light = panel_light(read, 90.0);
    EXPECT_TRUE(light.config().overdrive);
    EXPECT_EQ(light.lc_second_order().has_value(), second_order);
    // From black to mid-grey the overdriven frame drives above the grey (and without overdrive, the grey).
    EXPECT_GT(light.drive(0.0, 0.5), 0.5);
    EXPECT_EQ(panel_light(plain, 90.0).drive(0.0, 0.5), 0.5);
    std::filesystem::remove(path);
  }
  const std::string head = R"({"kind": "lcd", "name": "x", "p1": -0.1, "p2": 0.2, "p3": 0.5, "p4": 0, "gamma": 2.2, )";
  for (const std::string tail : {R"("overdrive": 1})", R"("overdrive": "yes"})", R"("overdrive": null})"}) {
    const std::filesystem::path file = write_file("bad_overdrive.json", head + tail);
    const std::string message = rejection("lcd:" + file.string());
    EXPECT_NE(message.find("\"overdrive\" must be true or false"), std::string::npos) << tail << ": " << message;
    std::filesystem::remove(file);
  }
  const std::filesystem::path off = write_file("overdrive_off.json", head + R"("overdrive": false})");
  EXPECT_FALSE(parse_panel("lcd:" + off.string()).lcd.overdrive);
  std::filesystem::remove(off);
}

// A misspelt field used to be ignored, leaving the panel at a default the preset meant to change: now it is an
// error that names it and the fields the kind takes, at the top level and inside the LC objects.
TEST(PanelPreset, UnknownFieldsAreErrorsNamingTheField) {
  const std::string lcd = R"({"kind": "lcd", "name": "x", "p1": -0.1, "p2": 0.2, "p3": 0.5, "p4": 0, "gamma": 2.2, )";
  const std::string oled = R"({"kind": "oled", "name": "x", "gamma": [2.2, 2.2, 2.2], "duty": 0.2, )";
  const std::vector<std::pair<std::string, std::vector<std::string>>> bad = {
      {lcd + R"("overdirve": true})", {"an LCD panel has an unknown field \"overdirve\"", "overdrive", "lc_response"}},
      {lcd + R"("lc_second_order": {"tau_s": 0.002, "damping": 1}})", {"\"lc_second_order\" has an unknown field "
                                                                          "\"damping\"", "damping_ratio"}},
      {lcd + R"("lc_response": {"tau_of_s": 0.002, "drive_ratio": 3, "drive_gamma": 2.2}})",
       {"\"lc_response\" has an unknown field \"tau_of_s\"", "tau_off_s"}},
      {oled + R"("dutty": 0.3})", {"an OLED panel has an unknown field \"dutty\"", "duty"}},
      // A field of the other kind is no field of this one.
      {oled + R"("p1": 0})", {"an OLED panel has an unknown field \"p1\""}},
  };
  for (const auto& [text, needles] : bad) {
    const std::filesystem::path file = write_file("unknown_field.json", text);
    const std::string message = rejection("lcd:" + file.string());
    EXPECT_NE(message.find("panel JSON"), std::string::npos) << text << ": " << message;
    for (const std::string& needle : needles) {
      EXPECT_NE(message.find(needle), std::string::npos) << text << ": " << message;
    }
    std::filesystem::remove(file);
    try {
      (void)nlohmann::json::parse(text).get<Panel>();
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needles.front()), std::string::npos) << e.what();
    }
  }
  // Every field to_json writes is one the reader takes: a panel with every optional field round-trips.
  Panel full = parse_panel("lcd");
  full.lcd.lc_second_order = LcSecondOrderParams{0.001, 1.2};
  full.lcd.overdrive = true;
  EXPECT_EQ(nlohmann::json(full).get<Panel>(), full);
  full.lcd.lc_second_order.reset();
  full.lcd.lc_response = LcResponseParams{0.003, 2.5, 2.0};
  EXPECT_EQ(nlohmann::json(full).get<Panel>(), full);
  EXPECT_EQ(nlohmann::json(parse_panel("rift")).get<Panel>(), parse_panel("rift"));
}

TEST(PanelPreset, FirstOrderCrystalIsSetByThePresetAndValidated) {
  const Panel plain = parse_panel("lcd");
  EXPECT_FALSE(nlohmann::json(plain).contains("lc_response"));  // at the defaults the JSON is what it always was
  Panel panel = plain;
  panel.lcd.lc_response = LcResponseParams{0.005, 4.0, 2.4};
  const std::filesystem::path path = write_file("first_order.json", nlohmann::json(panel).dump(2));
  const Panel read = parse_panel("lcd:" + path.string());
  std::filesystem::remove(path);
  EXPECT_EQ(read, panel);
  EXPECT_NE(read, plain);
  const double refresh = 90.0, period = 1.0 / refresh;
  const PanelLight light = panel_light(read, refresh);
  ASSERT_TRUE(light.lc_response().has_value());
  EXPECT_EQ(light.lc_response()->params(), (LcResponseParams{0.005, 4.0, 2.4}));
  // Falling has the elastic τ_off alone: white to black ends the frame at e^{−T/τ_off} (the closed form; the plain
  // panel's τ_off is 2 ms).
  EXPECT_NEAR(light.end_state(1.0, 0.0), std::exp(-period / 0.005), 1e-15);
  EXPECT_NEAR(panel_light(plain, refresh).end_state(1.0, 0.0), std::exp(-period / 0.002), 1e-15);
  // Rising to full drive: τ_on = τ_off / ((V_max / V_th)² − 1) = 5 ms / 15.
  EXPECT_NEAR(light.end_state(0.0, 1.0), 1.0 - std::exp(-period * 15.0 / 0.005), 1e-15);

  const std::string head = R"({"kind": "lcd", "name": "x", "p1": -0.1, "p2": 0.2, "p3": 0.5, "p4": 0, "gamma": 2.2, )";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"("lc_response": {"tau_off_s": 0, "drive_ratio": 3, "drive_gamma": 2.2}})", "'tau_off_s'"},
      {R"("lc_response": {"tau_off_s": 0.002, "drive_ratio": 1, "drive_gamma": 2.2}})", "'drive_ratio'"},
      {R"("lc_response": {"tau_off_s": 0.002, "drive_ratio": 3, "drive_gamma": 9}})", "'drive_gamma'"},
      {R"("lc_response": {"tau_off_s": 0.002, "drive_ratio": 3}})", "missing \"drive_gamma\""},
      {R"("lc_response": {"tau_off_s": "2ms", "drive_ratio": 3, "drive_gamma": 2.2}})",
       "\"tau_off_s\" must be a number"},
      {R"("lc_response": [0.002, 3, 2.2]})", "\"lc_response\" must be an object"},
      {R"("lc_response": {"tau_off_s": 0.004, "drive_ratio": 3, "drive_gamma": 2.2}, )"
       R"("lc_second_order": {"tau_s": 0.002, "damping_ratio": 1}})", "one LC model"},
  };
  for (const auto& [tail, needle] : bad) {
    const std::filesystem::path file = write_file("bad_first_order.json", head + tail);
    const std::string message = rejection("lcd:" + file.string());
    EXPECT_NE(message.find(needle), std::string::npos) << tail << ": " << message;
    EXPECT_NE(message.find("panel JSON"), std::string::npos) << message;
    std::filesystem::remove(file);
  }
}

}  // namespace
}  // namespace trm
