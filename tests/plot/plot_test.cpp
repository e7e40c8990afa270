// The plotting module: a figure becomes a PNG that decodes and shows something; a figure it cannot draw is
// refused with a message naming what is wrong, and leaves no file.
#include "trm/plot.hpp"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;
using namespace trm::plot;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(TRM_BINARY_DIR) / "test_plot_out" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Figure two_chart_figure() {
  Figure f;
  f.title = "errors # of a knob";  // '#' is PLplot's escape character: it must come out as written
  f.subtitle = "a subtitle";
  f.width = 900;
  f.height = 400;
  Chart lines;
  lines.title = "linear";
  lines.x.label = "frame";
  lines.y.label = "Mbit";
  lines.y.min = 0.0;
  lines.series.push_back({.label = "measured", .x = {0, 1, 2, 3, 4}, .y = {1, 2, std::nan(""), 2, 3}});
  lines.series.push_back({.label = "capacity", .x = {0, 4}, .y = {2.5, 2.5}, .dashed = true});
  Chart scatter;
  scatter.title = "log";
  scatter.x.scale = Scale::Log;
  scatter.y.scale = Scale::Log;
  scatter.y.nonpositive_on_edge = true;
  scatter.series.push_back({.label = "max",
                            .x = {1, 10, 100},
                            .y = {0.0, 0.5, 3.0},
                            .style = Style::LineAndPoints,
                            .point_labels = {"a", "b", "c"}});
  scatter.rings = {{10, 0.5}};
  scatter.rings_label = "base value";
  f.charts = {lines, scatter};
  return f;
}

void expect_no_file_left(const fs::path& dir) {
  for (const auto& entry : fs::directory_iterator(dir)) ADD_FAILURE() << "left behind: " << entry.path();
}

// The message of the exception write_png throws, or "" when it writes.
template <typename Exception>
std::string failure_of(const fs::path& path, const Figure& f) {
  try {
    write_png(path, f);
  } catch (const Exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Plot, WritesAPngThatDecodesAtTheAskedSizeAndShowsTheData) {
  const fs::path dir = fresh_dir("writes");
  const fs::path png = dir / "figure.png";
  write_png(png, two_chart_figure());
  const cv::Mat image = cv::imread(png.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 900);
  EXPECT_EQ(image.rows, 400);
  // Not blank: a white page with dark ink (frame, text) and colour (the series).
  cv::Mat grey;
  cv::extractChannel(image, grey, 1);
  double lo = 0, hi = 0;
  cv::minMaxLoc(grey, &lo, &hi);
  EXPECT_EQ(hi, 255.0);
  EXPECT_LT(lo, 64.0);
  const cv::Scalar mean = cv::mean(image);
  EXPECT_GT(mean[0], 200.0);  // mostly background
  int coloured = 0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3b p = image.at<cv::Vec3b>(y, x);
      if (std::abs(p[0] - p[2]) > 60) ++coloured;
    }
  }
  EXPECT_GT(coloured, 200);
  // Only the file: no staging sibling left.
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(Plot, WritesUnderADirectoryNameHoldingPlplotsFilePattern) {
  const fs::path dir = fresh_dir("family %n name");
  write_png(dir / "figure.png", two_chart_figure());
  EXPECT_FALSE(cv::imread((dir / "figure.png").string()).empty());
}

TEST(Plot, ReplacesAnEarlierPlotWhole) {
  const fs::path dir = fresh_dir("replaces");
  const fs::path png = dir / "figure.png";
  Figure f = two_chart_figure();
  write_png(png, f);
  f.width = 300;
  f.height = 200;
  f.charts.resize(1);
  write_png(png, f);
  const cv::Mat image = cv::imread(png.string(), cv::IMREAD_COLOR);
  EXPECT_EQ(image.cols, 300);
  EXPECT_EQ(image.rows, 200);
}

TEST(Plot, AChartWithOnlyANoteIsDrawn) {
  const fs::path dir = fresh_dir("note");
  Figure f;
  f.title = "nothing accepted";
  Chart empty;
  empty.note = "no value of this knob was accepted";
  f.charts = {empty};
  write_png(dir / "note.png", f);
  EXPECT_FALSE(cv::imread((dir / "note.png").string()).empty());
}

TEST(Plot, RefusesFiguresItCannotDrawAndLeavesNoFile) {
  const fs::path dir = fresh_dir("refuses");
  const fs::path png = dir / "figure.png";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto with_series = [](Series s) {
    Figure f;
    f.title = "bad";
    Chart c;
    c.title = "c";
    c.series.push_back(std::move(s));
    f.charts = {c};
    return f;
  };
  const Figure only_gaps = with_series({.label = "only gaps", .x = {0, 1}, .y = {nan, nan}});
  EXPECT_NE(failure_of<std::invalid_argument>(png, only_gaps).find("series 'only gaps' has no finite point"),
            std::string::npos);
  EXPECT_NE(failure_of<std::invalid_argument>(png, with_series({.label = "nothing"})).find("series 'nothing' is empty"),
            std::string::npos);
  const Figure ragged = with_series({.label = "ragged", .x = {0, 1}, .y = {1}});
  EXPECT_NE(failure_of<std::invalid_argument>(png, ragged).find("2 x but 1 y"), std::string::npos);

  Figure log = with_series({.label = "zero", .x = {1, 2}, .y = {0, 1}});
  log.charts[0].y.scale = Scale::Log;
  EXPECT_NE(failure_of<std::invalid_argument>(png, log).find("a logarithmic axis cannot show"), std::string::npos);

  Figure no_chart;
  no_chart.title = "empty";
  EXPECT_NE(failure_of<std::invalid_argument>(png, no_chart).find("plot 'empty': has no chart"), std::string::npos);

  Figure silent;
  silent.charts.resize(1);
  EXPECT_NE(failure_of<std::invalid_argument>(png, silent).find("no series and no note"), std::string::npos);

  Figure tiny = two_chart_figure();
  tiny.width = 10;
  EXPECT_NE(failure_of<std::invalid_argument>(png, tiny).find("size 10x400"), std::string::npos);

  Figure reversed = two_chart_figure();
  reversed.charts[0].x.min = 5.0;
  reversed.charts[0].x.max = 1.0;
  EXPECT_NE(failure_of<std::invalid_argument>(png, reversed).find("min must be below max"), std::string::npos);
  expect_no_file_left(dir);
}

TEST(Plot, AnUnwritableTargetIsAClearErrorAndLeavesNoFile) {
  const fs::path dir = fresh_dir("unwritable");
  const std::string missing_dir = failure_of<std::runtime_error>(dir / "no_such_dir" / "figure.png",
                                                                 two_chart_figure());
  EXPECT_NE(missing_dir.find("no_such_dir/figure.png"), std::string::npos) << missing_dir;
  fs::create_directory(dir / "a_directory.png");
  const std::string onto_dir = failure_of<std::runtime_error>(dir / "a_directory.png", two_chart_figure());
  EXPECT_NE(onto_dir.find("a_directory.png"), std::string::npos) << onto_dir;
  fs::remove(dir / "a_directory.png");
  expect_no_file_left(dir);
}

TEST(Plot, ConcurrentPlotsEachGetTheirOwnStream) {
  const fs::path dir = fresh_dir("concurrent");
  std::vector<std::thread> threads;
  for (int i = 0; i < 4; ++i) {
    threads.emplace_back([&dir, i] {
      Figure f = two_chart_figure();
      f.width = 400 + 10 * i;
      write_png(dir / ("figure" + std::to_string(i) + ".png"), f);
    });
  }
  for (std::thread& t : threads) t.join();
  for (int i = 0; i < 4; ++i) {
    const cv::Mat image = cv::imread((dir / ("figure" + std::to_string(i) + ".png")).string());
    ASSERT_FALSE(image.empty()) << i;
    EXPECT_EQ(image.cols, 400 + 10 * i);
  }
}
