// Charts written as PNG files: the one place trm draws a plot (PLplot through its pngcairo driver).
//
// A Figure is one PNG: a title, an optional subtitle and one or more charts side by side. A chart has two axes
// (linear or logarithmic), series drawn as lines and/or points, optional rings around points of interest (a base
// value, the chosen point of a front), per-point labels, a legend and a note. Ranges follow the data unless an
// axis fixes them.
//
// write_png() checks the whole figure before drawing, draws through a PLplot stream of its own (PLplot's state
// is global: renders are serialised, and PLplot's fatal errors become exceptions instead of ending the process)
// and writes through io::AtomicFile: the target holds the whole PNG or is left as it was.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace trm::plot {

enum class Scale { Linear, Log };

struct Axis {
  std::string label{};
  Scale scale = Scale::Linear;
  std::optional<double> min{}, max{};  // fixed ends (finite, min < max, positive on a log axis); default: the data's
  // Log axes only: a value <= 0 (an exact zero error, say) is drawn hollow on the axis' lower edge instead of
  // being refused.
  bool nonpositive_on_edge = false;
};

enum class Style { Line, Points, LineAndPoints };

struct Series {
  std::string label{};     // the legend entry; empty: not in the legend
  std::vector<double> x{};  // as many as y
  std::vector<double> y{};  // at least one finite point; a non-finite x or y is a gap that breaks the line
  Style style = Style::Line;
  bool dashed = false;
  std::optional<int> colour{};             // palette index (any int, wraps); default: the series' position
  std::vector<std::string> point_labels{}; // empty, or one per point, written beside it
};

struct Point {
  double x = 0, y = 0;
};

// Best: the inside corner that covers the least of the data.
enum class LegendPlace { Best, TopRight, TopLeft, BottomRight, BottomLeft, None };

struct Chart {
  std::string title{};
  Axis x{}, y{};
  std::vector<Series> series{};
  std::vector<Point> rings{};   // drawn as black rings around the points
  std::string rings_label{};    // the rings' legend entry; empty: not in the legend
  std::string note{};           // written inside the chart; a chart with no series must say why in its note
  LegendPlace legend = LegendPlace::Best;
};

struct Figure {
  std::string title{};
  std::string subtitle{};
  int width = 1200, height = 640;  // pixels, each in [kMinPixels, kMaxPixels]
  std::vector<Chart> charts{};     // left to right, at least one
};

inline constexpr int kMinPixels = 64;
inline constexpr int kMaxPixels = 16384;

// Checks the figure (std::invalid_argument naming the figure, chart and series at fault) and draws it into a
// PNG at `path` (std::runtime_error naming the file on a drawing or I/O failure). On any error nothing is left
// at `path` that was not there before.
void write_png(const std::filesystem::path& path, const Figure& figure);

}  // namespace trm::plot
