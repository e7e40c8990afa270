#include "trm/bandwidth.hpp"

#include "trm/atomic_file.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace trm::link {

namespace {

// Canvas geometry, pixels.
constexpr int kWidth = 1200, kHeight = 640;
constexpr int kLeft = 100, kRight = 30, kTop = 50, kBottom = 60;

// Series colours (OpenCV draws BGR): blue, orange, green, red, purple, brown.
const cv::Scalar kColours[] = {{180, 119, 31}, {14, 127, 255}, {44, 160, 44}, {40, 39, 214}, {189, 103, 148}, {75, 86, 140}};

std::string format_mbit(double bits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", bits / 1e6);
  return text;
}

// A "nice" tick step (1, 2 or 5 times a power of ten) giving about `target` ticks over `span`. The tick loops step
// by it, so a span it cannot divide into a bounded number of finite steps is an error, never an endless loop.
double tick_step(double span, int target) {
  if (!(std::isfinite(span) && span > 0.0)) throw std::invalid_argument("bandwidth plot: axis span is not finite");
  const double raw = span / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10.0 * magnitude;
  for (double m : {5.0, 2.0, 1.0})
    if (m * magnitude >= raw) step = m * magnitude;
  if (!(std::isfinite(step) && step > 0.0 && span / step <= 4.0 * target && span + step > span)) {
    throw std::invalid_argument("bandwidth plot: no finite tick step for an axis of " + std::to_string(span));
  }
  return step;
}

}  // namespace

PlotTrace::PlotTrace(std::string label, std::size_t max_buckets) : label_(std::move(label)), max_buckets_(max_buckets) {
  if (max_buckets_ < 2 || max_buckets_ % 2 != 0) {
    throw std::invalid_argument("plot trace: max_buckets must be even, >= 2");
  }
  buckets_.reserve(max_buckets_);
}

void PlotTrace::add(double bits) {
  const bool finite = std::isfinite(bits);
  if (count_ % width_ == 0) {
    if (buckets_.size() == max_buckets_) {
      // Full: pairs of buckets become one of twice the width, which leaves count_ on a bucket boundary.
      for (std::size_t i = 0; i < max_buckets_ / 2; ++i) {
        const Bucket& a = buckets_[2 * i];
        const Bucket& b = buckets_[2 * i + 1];
        buckets_[i] = {a.first, b.last, std::min(a.min, b.min), std::max(a.max, b.max)};
      }
      buckets_.resize(max_buckets_ / 2);
      width_ *= 2;
    }
    const double inf = std::numeric_limits<double>::infinity();
    buckets_.push_back({bits, bits, finite ? bits : inf, finite ? bits : -inf});
  } else {
    Bucket& b = buckets_.back();
    b.last = bits;
    if (finite) {
      b.min = std::min(b.min, bits);
      b.max = std::max(b.max, bits);
    }
  }
  ++count_;
}

void plot_bits_per_frame(const std::filesystem::path& path, std::span<const PlotSeries> series, double capacity_bits,
                         const std::string& title) {
  std::vector<PlotTrace> traces;
  for (const PlotSeries& s : series) {
    // One bucket per value (an even count, at least 2): the plot of the whole series.
    const std::size_t buckets = std::max<std::size_t>(2, (s.bits_per_frame.size() + 1) / 2 * 2);
    PlotTrace& trace = traces.emplace_back(s.label, buckets);
    for (double v : s.bits_per_frame) trace.add(v);
  }
  plot_bits_per_frame(path, std::span<const PlotTrace>(traces), capacity_bits, title);
}

void plot_bits_per_frame(const std::filesystem::path& path, std::span<const PlotTrace> series, double capacity_bits,
                         const std::string& title) {
  std::int64_t frames = 0;
  double y_max = capacity_bits > 0.0 ? capacity_bits : 0.0;
  for (const PlotTrace& s : series) {
    frames = std::max(frames, s.count());
    for (const PlotTrace::Bucket& b : s.buckets())
      if (b.min <= b.max) y_max = std::max(y_max, b.max);
  }
  if (y_max <= 0.0) y_max = 1.0;
  y_max *= 1.1;
  const double x_max = frames > 1 ? static_cast<double>(frames - 1) : 1.0;

  cv::Mat canvas(kHeight, kWidth, CV_8UC3, cv::Scalar::all(255));
  const int plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
  auto to_px = [&](double x, double y) {
    return cv::Point(kLeft + static_cast<int>(std::lround(x / x_max * plot_w)),
                     kTop + plot_h - static_cast<int>(std::lround(std::clamp(y, 0.0, y_max) / y_max * plot_h)));
  };
  const cv::Scalar black(0, 0, 0), grey(200, 200, 200);
  const int font = cv::FONT_HERSHEY_SIMPLEX;

  // Grid, ticks and labels.
  const double y_step = tick_step(y_max, 6);
  for (double y = 0.0; y <= y_max; y += y_step) {
    cv::line(canvas, to_px(0, y), to_px(x_max, y), grey, 1);
    cv::putText(canvas, format_mbit(y), to_px(0, y) + cv::Point(-80, 5), font, 0.45, black, 1, cv::LINE_AA);
  }
  const double x_step = std::max(1.0, tick_step(x_max, 10));
  for (double x = 0.0; x <= x_max; x += x_step) {
    cv::line(canvas, to_px(x, 0), to_px(x, 0) + cv::Point(0, 5), black, 1);
    cv::putText(canvas, std::to_string(static_cast<long long>(x)), to_px(x, 0) + cv::Point(-8, 22), font, 0.45, black,
                1, cv::LINE_AA);
  }
  cv::rectangle(canvas, cv::Point(kLeft, kTop), cv::Point(kLeft + plot_w, kTop + plot_h), black, 1);
  cv::putText(canvas, "link frame", cv::Point(kLeft + plot_w / 2 - 40, kHeight - 15), font, 0.55, black, 1, cv::LINE_AA);
  cv::putText(canvas, "Mbit", cv::Point(15, kTop - 10), font, 0.55, black, 1, cv::LINE_AA);
  cv::putText(canvas, title, cv::Point(kLeft, 30), font, 0.65, black, 1, cv::LINE_AA);

  // Capacity: dashed.
  if (capacity_bits > 0.0) {
    const cv::Point a = to_px(0, capacity_bits), b = to_px(x_max, capacity_bits);
    for (int x = a.x; x < b.x; x += 16) cv::line(canvas, {x, a.y}, {std::min(x + 8, b.x), a.y}, black, 1);
    cv::putText(canvas, "link capacity per frame", a + cv::Point(6, -6), font, 0.45, black, 1, cv::LINE_AA);
  }

  // Series, then the legend on a white box so that no line runs through it.
  for (std::size_t i = 0; i < series.size(); ++i) {
    const cv::Scalar colour = kColours[i % std::size(kColours)];
    const std::vector<PlotTrace::Bucket>& b = series[i].buckets();
    const std::int64_t w = series[i].bucket_width(), count = series[i].count();
    for (std::size_t k = 0; k < b.size(); ++k) {
      const auto start = static_cast<std::int64_t>(k) * w;
      const std::int64_t end = std::min(start + w, count) - 1;  // index of the bucket's last value
      if (w > 1 && b[k].min <= b[k].max) {
        const double x = 0.5 * static_cast<double>(start + end);
        cv::line(canvas, to_px(x, b[k].min), to_px(x, b[k].max), colour, 2, cv::LINE_AA);
      }
      if (k + 1 < b.size() && std::isfinite(b[k].last) && std::isfinite(b[k + 1].first)) {
        const auto x = static_cast<double>(end);
        cv::line(canvas, to_px(x, b[k].last), to_px(x + 1.0, b[k + 1].first), colour, 2, cv::LINE_AA);
      }
    }
    if (count == 1 && std::isfinite(b[0].first)) cv::circle(canvas, to_px(0, b[0].first), 3, colour, cv::FILLED);
  }
  if (!series.empty()) {
    const cv::Point corner(kLeft + plot_w - 340, kTop + 8);
    cv::rectangle(canvas, corner, corner + cv::Point(330, 10 + 20 * static_cast<int>(series.size())),
                  cv::Scalar::all(255), cv::FILLED);
    cv::rectangle(canvas, corner, corner + cv::Point(330, 10 + 20 * static_cast<int>(series.size())), grey, 1);
    for (std::size_t i = 0; i < series.size(); ++i) {
      const cv::Point legend = corner + cv::Point(10, 15 + static_cast<int>(i) * 20);
      cv::line(canvas, legend, legend + cv::Point(25, 0), kColours[i % std::size(kColours)], 3);
      cv::putText(canvas, series[i].label(), legend + cv::Point(32, 5), font, 0.45, black, 1, cv::LINE_AA);
    }
  }

  std::vector<std::uint8_t> png;
  if (!cv::imencode(".png", canvas, png)) throw std::runtime_error("cannot encode plot '" + path.string() + "' as PNG");
  io::write_file_atomically(path, png);
}

}  // namespace trm::link
