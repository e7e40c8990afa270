// `--panel lcd:FILE.json`: an LCD preset file read through the one panel parser.
#include <gtest/gtest.h>

#include "trm/panel.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
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

}  // namespace
}  // namespace trm
