#include "trm/plot.hpp"

#include "trm/atomic_file.hpp"

#include <plplot.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <mutex>
#include <string_view>

namespace trm::plot {

namespace {

constexpr const char* kDevice = "pngcairo";

// cmap0: PLplot draws the page in colour 0; 1 to 3 are the frame, grid and secondary text; series colours follow.
constexpr int kBackground = 0, kInk = 1, kGrid = 2, kMutedInk = 3, kFirstSeriesColour = 4;
constexpr std::array<std::array<PLINT, 3>, 14> kColourMap = {{
    {255, 255, 255}, {0, 0, 0}, {215, 215, 215}, {90, 90, 90},
    // The Tableau 10 palette: ten hues that stay apart from each other and from the white page.
    {31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {214, 39, 40}, {148, 103, 189},
    {140, 86, 75}, {227, 119, 194}, {127, 127, 127}, {188, 189, 34}, {23, 190, 207}}};
constexpr int kSeriesColours = static_cast<int>(kColourMap.size()) - kFirstSeriesColour;

constexpr const char* kDot = "●";
constexpr const char* kHollowDot = "○";
constexpr const char* kRing = "◯";
constexpr double kDotScale = 0.7, kRingScale = 1.3;  // of the text height

// Text has a fixed size in pixels, whatever the page size: PLplot sizes it in millimetres, at the page's
// resolution.
constexpr double kPixelsPerInch = 90, kTextMillimetres = 4.4;

// Layout of one chart inside its column, pixels.
constexpr double kLeftMargin = 86, kRightMargin = 22, kBottomMargin = 58, kChartTitleBand = 34;

class FatalPlplotError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// PLplot's plexit() calls this and would end the process if it returned: unwinding out of it abandons the
// failed call instead (the library's C frames carry unwind tables on the platforms trm builds on).
int throw_on_fatal(const char* message) {
  throw FatalPlplotError(std::string(message ? message : "unknown error"));
}

// PLplot's streams, device table and error handlers are process-wide.
std::mutex& plplot_mutex() {
  static std::mutex mutex;
  return mutex;
}

// PLplot reads '#' as the start of an escape sequence in every string it draws.
std::string escaped(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    out += c;
    if (c == '#') out += '#';
  }
  return out;
}

std::string quoted(const std::string& text) { return std::string("'").append(text).append("'"); }

std::string figure_name(const Figure& f) {
  return std::string("plot ").append(quoted(f.title.empty() ? std::string("(untitled)") : f.title));
}

// ---- checking the figure ----

std::string chart_name(const Figure& f, std::size_t chart) {
  std::string name = figure_name(f);
  if (f.charts.size() > 1 || !f.charts[chart].title.empty()) {
    name.append(", chart ").append(std::to_string(chart + 1));
    if (!f.charts[chart].title.empty()) name.append(" ").append(quoted(f.charts[chart].title));
  }
  return name;
}

void check_axis(const Axis& a, const std::string& where, const char* which) {
  const auto fail = [&](const std::string& why) {
    throw std::invalid_argument(where + ": " + which + " axis " + why);
  };
  for (const std::optional<double>& end : {a.min, a.max}) {
    if (!end) continue;
    if (!std::isfinite(*end)) fail("end is not finite");
    if (a.scale == Scale::Log && *end <= 0) fail("is logarithmic but has an end <= 0");
  }
  if (a.min && a.max && !(*a.min < *a.max)) fail("min must be below max");
  if (a.nonpositive_on_edge && a.scale != Scale::Log) fail("draws values <= 0 on its edge but is not logarithmic");
}

// A value the axis can place: finite, and positive on a log axis unless that axis puts the others on its edge.
bool placeable(const Axis& a, double v) {
  return std::isfinite(v) && (a.scale == Scale::Linear || v > 0 || a.nonpositive_on_edge);
}

void check(const Figure& f) {
  const std::string figure = figure_name(f);
  if (f.width < kMinPixels || f.width > kMaxPixels || f.height < kMinPixels || f.height > kMaxPixels) {
    throw std::invalid_argument(figure + ": size " + std::to_string(f.width) + "x" + std::to_string(f.height) +
                                " is outside " + std::to_string(kMinPixels) + ".." + std::to_string(kMaxPixels) +
                                " pixels a side");
  }
  if (f.charts.empty()) throw std::invalid_argument(figure + ": has no chart");
  for (std::size_t c = 0; c < f.charts.size(); ++c) {
    const Chart& chart = f.charts[c];
    const std::string where = chart_name(f, c);
    check_axis(chart.x, where, "x");
    check_axis(chart.y, where, "y");
    if (chart.series.empty() && chart.note.empty()) {
      throw std::invalid_argument(where + ": has no series and no note saying why");
    }
    for (const Series& s : chart.series) {
      const std::string series = where + ": series " + quoted(s.label);
      if (s.x.size() != s.y.size()) {
        throw std::invalid_argument(series + " has " + std::to_string(s.x.size()) + " x but " +
                                    std::to_string(s.y.size()) + " y values");
      }
      if (s.x.empty()) throw std::invalid_argument(series + " is empty");
      if (!s.point_labels.empty() && s.point_labels.size() != s.x.size()) {
        throw std::invalid_argument(series + " has " + std::to_string(s.point_labels.size()) + " point labels for " +
                                    std::to_string(s.x.size()) + " points");
      }
      bool any_finite = false;
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        any_finite = true;
        if (!placeable(chart.x, s.x[i]) || !placeable(chart.y, s.y[i])) {
          throw std::invalid_argument(series + " has the point (" + std::to_string(s.x[i]) + ", " +
                                      std::to_string(s.y[i]) + "), which a logarithmic axis cannot show");
        }
      }
      if (!any_finite) throw std::invalid_argument(series + " has no finite point");
    }
    for (const Point& p : chart.rings) {
      if (!placeable(chart.x, p.x) || !placeable(chart.y, p.y)) {
        throw std::invalid_argument(where + ": a ring at (" + std::to_string(p.x) + ", " + std::to_string(p.y) +
                                    ") is not a point its axes can show");
      }
    }
  }
}

// ---- ranges, in drawing coordinates (log10 of the value on a log axis) ----

struct Range {
  double lo, hi;
};

Range range_of(const Axis& a, const std::vector<double>& values) {
  const bool log = a.scale == Scale::Log;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values) {
    if (!std::isfinite(v) || (log && v <= 0)) continue;
    lo = std::min(lo, log ? std::log10(v) : v);
    hi = std::max(hi, log ? std::log10(v) : v);
  }
  if (a.min) lo = log ? std::log10(*a.min) : *a.min;
  if (a.max) hi = log ? std::log10(*a.max) : *a.max;
  if (!(lo <= hi)) {  // nothing to place on this axis but edge values
    if (a.min) return {lo, log ? lo + 1 : lo + 1};
    if (a.max) return {hi - 1, hi};
    return {log ? -1.0 : 0.0, log ? 0.0 : 1.0};
  }
  if (log) {
    // Whole decades, so that every tick is labelled; one decade at least.
    if (!a.min) lo = std::floor(lo);
    if (!a.max) hi = std::ceil(hi);
    if (hi <= lo) {
      if (!a.min) lo = hi - 1;
      else hi = lo + 1;
    }
    return {lo, hi};
  }
  if (hi - lo <= 1e-12 * std::max(std::abs(lo), std::abs(hi))) {
    const double pad = lo == 0 ? 1.0 : std::abs(lo) * 0.1;
    if (!a.min) lo -= pad;
    if (!a.max) hi += pad;
    if (hi <= lo) hi = lo + pad;
    return {lo, hi};
  }
  const double pad = 0.04 * (hi - lo);
  if (!a.min) lo -= pad;
  if (!a.max) hi += pad;
  return {lo, hi};
}

struct Placed {
  double x, y;
  bool on_edge;  // a value <= 0 drawn on a log axis' lower edge
};

// Where a point goes: std::nullopt for a gap.
std::optional<Placed> place(const Chart& c, const Range& xr, const Range& yr, double x, double y) {
  if (!std::isfinite(x) || !std::isfinite(y)) return std::nullopt;
  Placed p{x, y, false};
  if (c.x.scale == Scale::Log) {
    p.on_edge = x <= 0;
    p.x = x > 0 ? std::log10(x) : xr.lo;
  }
  if (c.y.scale == Scale::Log) {
    p.on_edge = p.on_edge || y <= 0;
    p.y = y > 0 ? std::log10(y) : yr.lo;
  }
  return p;
}

PLINT colour_of(const Series& s, std::size_t position) {
  const int index = s.colour.value_or(static_cast<int>(position));
  return kFirstSeriesColour + ((index % kSeriesColours) + kSeriesColours) % kSeriesColours;
}

// ---- drawing ----

// One PLplot stream for one figure: made current on construction, ended and the previous stream restored on
// destruction. Recoverable PLplot errors (plabort) land in this stream's error slot instead of stderr.
class Stream {
 public:
  Stream() {
    plgstrm(&previous_);
    plmkstrm(&id_);
    if (id_ < 0) {
      plsstrm(previous_);
      throw std::runtime_error("PLplot has no free stream");
    }
    plsError(&error_code_, error_message_.data());
  }
  ~Stream() {
    // After a fatal error the stream's state is unknown: it is left allocated rather than risk a second one.
    if (!abandoned_) {
      try {
        plend1();
      } catch (const FatalPlplotError&) {  // the plot has failed already; the first error is the one reported
      }
    }
    plsstrm(previous_);
  }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;

  void end() {
    plend1();
    abandoned_ = true;  // nothing left to end
  }
  void abandon() { abandoned_ = true; }
  // Throws when a PLplot call since the stream began reported an error.
  void check(const char* during) const {
    if (error_code_ != 0) {
      std::string message(error_message_.data());
      while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
      while (!message.empty() && message.front() == '\n') message.erase(0, 1);
      throw std::runtime_error(std::string("PLplot failed ") + during + ": " + message);
    }
  }

 private:
  PLINT previous_ = 0, id_ = -1;
  PLINT error_code_ = 0;
  std::array<char, 4096> error_message_{};  // PLplot formats into it without a bound; its messages are short
  bool abandoned_ = false;
};

void require_device() {
  std::array<const char*, 256> menu{}, names{};
  const char** menu_ptr = menu.data();
  const char** names_ptr = names.data();
  int count = static_cast<int>(names.size());
  plgDevs(&menu_ptr, &names_ptr, &count);
  for (int i = 0; i < count; ++i) {
    if (names[i] && std::string_view(names[i]) == kDevice) return;
  }
  // Without the driver PLplot would ask for a device on stdin.
  throw std::runtime_error(std::string("PLplot has no '") + kDevice +
                           "' driver (Debian package plplot-driver-cairo; tools/setup.sh installs it)");
}

void text_height(double scale) { plschr(kTextMillimetres, scale); }

void draw_series(const Chart& chart, const Range& xr, const Range& yr) {
  for (std::size_t k = 0; k < chart.series.size(); ++k) {
    const Series& s = chart.series[k];
    plcol0(colour_of(s, k));
    plwidth(2.0);
    if (s.dashed) {
      const PLINT mark = 4000, space = 2500;  // micrometres
      plstyl(1, &mark, &space);
    }
    std::vector<PLFLT> run_x, run_y;
    const auto flush_run = [&] {
      if (run_x.size() >= 2) plline(static_cast<PLINT>(run_x.size()), run_x.data(), run_y.data());
      if (run_x.size() == 1 && s.style == Style::Line) {
        text_height(kDotScale);
        plstring(1, run_x.data(), run_y.data(), kDot);
        text_height(1.0);
      }
      run_x.clear();
      run_y.clear();
    };
    std::vector<Placed> placed;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const std::optional<Placed> p = place(chart, xr, yr, s.x[i], s.y[i]);
      if (!p) {
        flush_run();
        continue;
      }
      placed.push_back(*p);
      if (s.style != Style::Points) {
        run_x.push_back(p->x);
        run_y.push_back(p->y);
      }
    }
    flush_run();
    if (s.dashed) plstyl(0, nullptr, nullptr);
    if (s.style != Style::Line) {
      text_height(kDotScale);
      for (const Placed& p : placed) {
        PLFLT x = p.x, y = p.y;
        plstring(1, &x, &y, p.on_edge ? kHollowDot : kDot);
      }
      text_height(1.0);
    }
    if (!s.point_labels.empty()) {
      plcol0(kMutedInk);
      text_height(0.75);
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        const std::optional<Placed> p = place(chart, xr, yr, s.x[i], s.y[i]);
        if (!p || s.point_labels[i].empty()) continue;
        const std::string beside = "   " + escaped(s.point_labels[i]);  // clear of the marker
        plptex(p->x, p->y, 1.0, 0.0, 0.0, beside.c_str());
      }
      text_height(1.0);
    }
  }
  plwidth(1.0);
  plcol0(kInk);
  for (const Point& r : chart.rings) {
    const std::optional<Placed> p = place(chart, xr, yr, r.x, r.y);
    PLFLT x = p->x, y = p->y;
    text_height(kRingScale);
    plstring(1, &x, &y, kRing);
    text_height(1.0);
  }
}

// The corner whose legend-sized box holds the fewest drawn points, line segments sampled along their length.
LegendPlace least_covered_corner(const Chart& chart, const Range& xr, const Range& yr) {
  constexpr double kBoxWidth = 0.45, kBoxHeight = 0.4;  // of the chart, about what a legend of a few entries takes
  constexpr std::array<LegendPlace, 4> kCorners = {LegendPlace::TopRight, LegendPlace::TopLeft,
                                                   LegendPlace::BottomRight, LegendPlace::BottomLeft};
  std::array<std::int64_t, 4> covered{};
  const auto count = [&](const Placed& p) {
    const double u = (p.x - xr.lo) / (xr.hi - xr.lo), v = (p.y - yr.lo) / (yr.hi - yr.lo);
    const bool right = u >= 1 - kBoxWidth, left = u <= kBoxWidth, top = v >= 1 - kBoxHeight, bottom = v <= kBoxHeight;
    covered[0] += top && right;
    covered[1] += top && left;
    covered[2] += bottom && right;
    covered[3] += bottom && left;
  };
  for (const Series& s : chart.series) {
    std::optional<Placed> previous;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const std::optional<Placed> p = place(chart, xr, yr, s.x[i], s.y[i]);
      if (p) count(*p);
      if (p && previous && s.style != Style::Points) {
        for (int k = 1; k < 8; ++k) {
          const double t = k / 8.0;
          count({previous->x + t * (p->x - previous->x), previous->y + t * (p->y - previous->y), false});
        }
      }
      previous = p;
    }
  }
  return kCorners[static_cast<std::size_t>(std::min_element(covered.begin(), covered.end()) - covered.begin())];
}

void draw_legend(const Chart& chart, const Range& xr, const Range& yr) {
  if (chart.legend == LegendPlace::None) return;
  std::vector<std::string> texts;
  std::vector<PLINT> options, text_colours, line_colours, line_styles, symbol_colours, symbol_numbers, box_colours,
      box_patterns;
  std::vector<PLFLT> line_widths, symbol_scales, box_scales, box_line_widths;
  std::vector<const char*> symbols;
  const auto add = [&](const std::string& label, bool line, bool dashed, bool symbol, PLINT colour, const char* glyph,
                       PLFLT glyph_scale) {
    texts.push_back(escaped(label));
    options.push_back((line ? PL_LEGEND_LINE : 0) | (symbol ? PL_LEGEND_SYMBOL : 0) |
                      (!line && !symbol ? PL_LEGEND_NONE : 0));
    text_colours.push_back(kInk);
    line_colours.push_back(colour);
    line_styles.push_back(dashed ? 2 : 1);
    line_widths.push_back(2.0);
    symbol_colours.push_back(colour);
    symbol_scales.push_back(glyph_scale);
    symbol_numbers.push_back(1);
    symbols.push_back(glyph);
    box_colours.push_back(kBackground);
    box_patterns.push_back(0);
    box_scales.push_back(1.0);
    box_line_widths.push_back(1.0);
  };
  for (std::size_t k = 0; k < chart.series.size(); ++k) {
    const Series& s = chart.series[k];
    if (s.label.empty()) continue;
    add(s.label, s.style != Style::Points, s.dashed, s.style != Style::Line, colour_of(s, k), kDot, kDotScale);
  }
  if (!chart.rings.empty() && !chart.rings_label.empty()) {
    add(chart.rings_label, false, false, true, kInk, kRing, kRingScale);
  }
  if (texts.empty()) return;
  std::vector<const char*> text_pointers;
  for (const std::string& t : texts) text_pointers.push_back(t.c_str());

  PLINT position = PL_POSITION_INSIDE;
  switch (chart.legend == LegendPlace::Best ? least_covered_corner(chart, xr, yr) : chart.legend) {
    case LegendPlace::TopRight: position |= PL_POSITION_TOP | PL_POSITION_RIGHT; break;
    case LegendPlace::TopLeft: position |= PL_POSITION_TOP | PL_POSITION_LEFT; break;
    case LegendPlace::BottomRight: position |= PL_POSITION_BOTTOM | PL_POSITION_RIGHT; break;
    case LegendPlace::BottomLeft: position |= PL_POSITION_BOTTOM | PL_POSITION_LEFT; break;
    case LegendPlace::Best:
    case LegendPlace::None: return;
  }
  const auto n = static_cast<PLINT>(texts.size());
  PLFLT width = 0, height = 0;
  pllegend(&width, &height, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX, position, 0.02, 0.03, 0.07, kBackground,
           kGrid, 1, n, 1, n, options.data(), 1.0, 0.8, 2.0, 0.0, text_colours.data(), text_pointers.data(),
           box_colours.data(), box_patterns.data(), box_scales.data(), box_line_widths.data(), line_colours.data(),
           line_styles.data(), line_widths.data(), symbol_colours.data(), symbol_scales.data(), symbol_numbers.data(),
           symbols.data());
  pllsty(1);
}

std::vector<double> values_of(const Chart& c, bool x) {
  std::vector<double> v;
  for (const Series& s : c.series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) v.push_back(x ? s.x[i] : s.y[i]);
    }
  }
  for (const Point& p : c.rings) v.push_back(x ? p.x : p.y);
  return v;
}

void draw_chart(const Chart& chart, double left, double right, double bottom, double top) {
  plvpor(left, right, bottom, top);
  const Range xr = range_of(chart.x, values_of(chart, true));
  const Range yr = range_of(chart.y, values_of(chart, false));
  plwind(xr.lo, xr.hi, yr.lo, yr.hi);

  const bool xlog = chart.x.scale == Scale::Log, ylog = chart.y.scale == Scale::Log;
  plcol0(kGrid);
  plwidth(1.0);
  plbox(xlog ? "gl" : "g", 0.0, 0, ylog ? "gl" : "g", 0.0, 0);
  plcol0(kInk);
  text_height(0.85);
  plbox(xlog ? "bcnstl" : "bcnst", 0.0, 0, ylog ? "bcnstlv" : "bcnstv", 0.0, 0);
  text_height(1.0);
  if (!chart.title.empty()) plmtex("t", 1.2, 0.0, 0.0, escaped(chart.title).c_str());
  text_height(0.9);
  if (!chart.x.label.empty()) plmtex("b", 3.0, 0.5, 0.5, escaped(chart.x.label).c_str());
  if (!chart.y.label.empty()) plmtex("l", 5.2, 0.5, 0.5, escaped(chart.y.label).c_str());
  text_height(1.0);

  draw_series(chart, xr, yr);
  draw_legend(chart, xr, yr);
  if (!chart.note.empty()) {
    plcol0(kMutedInk);
    plmtex("t", -2.0, 0.5, 0.5, escaped(chart.note).c_str());
    plcol0(kInk);
  }
}

void render(const std::filesystem::path& file, const Figure& f) {
  Stream stream;
  try {
    require_device();
    plsdev(kDevice);
    // PLplot gets an open file, not the name: it would rewrite a name holding "%n" (its family-file pattern).
    std::FILE* out = std::fopen(file.c_str(), "wb");
    if (!out) throw std::runtime_error(std::string("cannot open the staging file: ") + std::strerror(errno));
    plsfile(out);
    plspage(kPixelsPerInch, kPixelsPerInch, f.width, f.height, 0, 0);
    for (std::size_t i = 0; i < kColourMap.size(); ++i) {
      plscol0(static_cast<PLINT>(i), kColourMap[i][0], kColourMap[i][1], kColourMap[i][2]);
    }
    plinit();
    PLINT level = 0;
    plglevel(&level);
    if (level == 0) std::fclose(out);  // from plinit on, PLplot closes it when the stream ends
    stream.check("to start the page");
    pladv(0);

    // The figure's title band, then the charts side by side under it; margins in pixels.
    const double w = f.width, h = f.height;
    double band = 8;
    plvpor(0.0, 1.0, 0.0, 1.0);
    plcol0(kInk);
    if (!f.title.empty()) {
      text_height(1.1);
      plmtex("t", -1.6, 0.01, 0.0, escaped(f.title).c_str());
      band += 24;
    }
    if (!f.subtitle.empty()) {
      plcol0(kMutedInk);
      text_height(0.85);
      plmtex("t", f.title.empty() ? -1.6 : -3.6, 0.01, 0.0, escaped(f.subtitle).c_str());
      plcol0(kInk);
      band += 20;
    }
    text_height(1.0);
    const double columns = static_cast<double>(f.charts.size());
    for (std::size_t i = 0; i < f.charts.size(); ++i) {
      const double column_left = static_cast<double>(i) / columns, column_right = (i + 1.0) / columns;
      draw_chart(f.charts[i], column_left + kLeftMargin / w, column_right - kRightMargin / w, kBottomMargin / h,
                 1.0 - (band + kChartTitleBand) / h);
      stream.check("while drawing");
    }
    stream.end();
    stream.check("to write the page");
  } catch (const FatalPlplotError& e) {
    stream.abandon();
    throw std::runtime_error(std::string("PLplot failed: ") + e.what());
  }
}

// PLplot does not report a failed write of the page (a full disk, say): a PNG is whole when it begins with the
// signature and ends with the IEND chunk.
void require_whole_png(const std::filesystem::path& file) {
  constexpr std::string_view kSignature("\x89PNG\r\n\x1a\n", 8);
  constexpr std::string_view kEnd("\0\0\0\0IEND\xae\x42\x60\x82", 12);
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < kSignature.size() + kEnd.size() || !bytes.starts_with(kSignature) ||
      !bytes.ends_with(kEnd)) {
    throw std::runtime_error("PLplot wrote no whole PNG (" + std::to_string(bytes.size()) + " bytes; disk full?)");
  }
}

}  // namespace

void write_png(const std::filesystem::path& path, const Figure& figure) {
  check(figure);
  io::AtomicFile file(path);
  try {
    std::lock_guard lock(plplot_mutex());
    plsexit(&throw_on_fatal);
    render(file.staging_path(), figure);
    require_whole_png(file.staging_path());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("cannot plot '" + io::shown(path) + "': " + e.what());
  }
  file.commit();
}

}  // namespace trm::plot

#if defined(__SANITIZE_ADDRESS__)
// Fontconfig, which pango asks for the plots' fonts, keeps its pattern caches unreferenced until the process ends;
// LeakSanitizer would report them at exit of every program that plots.
extern "C" const char* __lsan_default_suppressions() { return "leak:libfontconfig.so\n"; }
// ... and would list the suppressed leaks on stderr at every exit, into the output the tests read.
extern "C" const char* __lsan_default_options() { return "print_suppressions=0"; }
#endif
