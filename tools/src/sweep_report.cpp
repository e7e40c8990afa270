#include "sweep_report.hpp"

#include "trm/encoder_json.hpp"
#include "trm/metrics.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>

namespace trm::cli {

namespace {

// ---- text formatting ----

std::string fixed_text(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

std::string general(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.9g", v);
  return buffer;
}

std::string scientific(double v) {
  if (v == 0.0) return "0";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2e", v);
  return buffer;
}

// Identical share, rounded down so that anything short of all codes never reads as 100 %.
std::string percent_text(const SweepPoint& p) {
  if (p.differing == 0) return "100 %";
  return fixed_text(std::floor(p.identical_percent * 1e4) / 1e4, 4) + " %";
}

std::string kib(std::int64_t bits) { return fixed_text(static_cast<double>(bits) / 8.0 / 1024.0, 1); }

std::string signed_kib(std::int64_t bits) {
  if (bits == 0) return "0";
  return std::string(bits > 0 ? "+" : "−").append(kib(std::abs(bits)));
}

std::string ms(double seconds) { return fixed_text(seconds * 1e3, 2); }

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out.push_back('"');
    out.push_back(c == '\n' ? ' ' : c);
  }
  out.push_back('"');
  return out;
}

std::string md_cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out.append("\\|"); else out.push_back(c);
  }
  return out;
}

std::string value_text(const SweepPoint& p) {
  if (!p.is_default) return std::to_string(p.value);
  return std::string("**").append(std::to_string(p.value)).append("** (base)");
}

std::string source_text(const SweepOptions& o) {
  return o.pipeline.input.empty() ? o.pipeline.scene : o.pipeline.input;
}

std::string header_line(const SweepResult& r) {
  std::ostringstream s;
  const auto& o = r.options.pipeline;
  s << source_text(r.options) << " " << r.size.width << "x" << r.size.height << " (reduced " << r.reduced.width << "x"
    << r.reduced.height << "), " << r.views << " views, r = " << o.encoder.reduction << ", " << o.panel.name << ", "
    << o.encoder.bits << "-bit link, " << o.output_bits << "-bit drive";
  return s.str();
}

// ---- plots ----

struct Axis {
  double lo = 0, hi = 1;
  bool log = false;
  std::string label;
};

double nice_step(double raw) {
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * magnitude >= raw) return m * magnitude;
  }
  return 10.0 * magnitude;
}

// An axis over the values; logarithmic when allowed, all positive and spanning at least a factor of 8.
Axis make_axis(const std::vector<double>& values, bool allow_log, std::string label) {
  Axis a;
  a.label = std::move(label);
  double lo = *std::min_element(values.begin(), values.end());
  double hi = *std::max_element(values.begin(), values.end());
  if (allow_log && lo > 0 && hi / lo >= 8.0) {
    a.log = true;
    a.lo = std::pow(10.0, std::floor(std::log10(lo)));
    a.hi = std::pow(10.0, std::ceil(std::log10(hi)));
    if (a.hi <= a.lo) a.hi = a.lo * 10.0;
    return a;
  }
  if (hi - lo <= std::abs(hi) * 1e-9) {
    const double pad = std::max(std::abs(lo) * 0.1, 1e-9);
    lo -= pad;
    hi += pad;
  }
  const double step = nice_step((hi - lo) / 5.0);
  a.lo = std::floor(lo / step) * step;
  a.hi = std::ceil(hi / step) * step;
  return a;
}

// Error axis (log): decades around the positive values; zeros are drawn on the bottom edge.
Axis error_axis(const std::vector<std::vector<double>>& series) {
  double lo = 0, hi = 0;
  for (const auto& s : series) {
    for (double v : s) {
      if (v <= 0) continue;
      lo = lo == 0 ? v : std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  Axis a;
  a.log = true;
  a.label = "error vs reference (output LSB), log; 0 on the bottom edge";
  if (hi == 0) {
    a.lo = 1e-4;
    a.hi = 1.0;
    return a;
  }
  a.lo = std::pow(10.0, std::floor(std::log10(lo)) - (lo == hi ? 1 : 0));
  a.hi = std::pow(10.0, std::ceil(std::log10(hi * 2.0)));  // headroom for the value labels above the markers
  return a;
}

double unit(const Axis& a, double v) {
  if (a.log) {
    if (v <= 0) return 0.0;
    return (std::log10(v) - std::log10(a.lo)) / (std::log10(a.hi) - std::log10(a.lo));
  }
  return (v - a.lo) / (a.hi - a.lo);
}

std::vector<double> ticks(const Axis& a) {
  std::vector<double> t;
  if (a.log) {
    const int decades = static_cast<int>(std::lround(std::log10(a.hi / a.lo)));
    for (double d = a.lo; d <= a.hi * 1.0001; d *= 10.0) {
      for (double m : decades <= 2 ? std::vector<double>{1, 2, 5} : std::vector<double>{1}) {
        if (m * d <= a.hi * 1.0001) t.push_back(m * d);
      }
    }
    return t;
  }
  const double step = nice_step((a.hi - a.lo) / 5.0);
  for (double v = a.lo; v <= a.hi + step * 1e-6; v += step) t.push_back(std::abs(v) < step * 1e-9 ? 0.0 : v);
  return t;
}

std::string tick_text(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

const int kFont = cv::FONT_HERSHEY_SIMPLEX;

void text(cv::Mat& canvas, const std::string& s, cv::Point at, double scale = 0.42,
          cv::Scalar colour = cv::Scalar(0, 0, 0)) {
  cv::putText(canvas, s, at, kFont, scale, colour, 1, cv::LINE_AA);
}

int text_width(const std::string& s, double scale = 0.42) {
  int baseline = 0;
  return cv::getTextSize(s, kFont, scale, 1, &baseline).width;
}

struct Series {
  std::string label;
  cv::Scalar colour;  // RGB
  std::vector<double> y;
};

// One panel: error series against x, points in value order joined by lines when `join`; the base point ringed;
// `labels` written beside the first series' markers.
void draw_panel(cv::Mat& canvas, cv::Rect area, const std::string& title, const Axis& xa, const std::vector<double>& x,
                const Axis& ya, const std::vector<Series>& series, int base_index, bool join,
                const std::vector<std::string>& labels) {
  const cv::Rect plot(area.x + 62, area.y + 44, area.width - 80, area.height - 100);
  const cv::Scalar grid(225, 225, 225), black(0, 0, 0);
  text(canvas, title, cv::Point(area.x + 10, area.y + 18), 0.5);
  text(canvas, ya.label, cv::Point(area.x + 10, area.y + 36), 0.38, cv::Scalar(90, 90, 90));
  const auto px = [&](double v) { return plot.x + static_cast<int>(std::lround(unit(xa, v) * plot.width)); };
  const auto py = [&](double v) {
    return plot.y + plot.height - static_cast<int>(std::lround(std::clamp(unit(ya, v), 0.0, 1.0) * plot.height));
  };
  for (double t : ticks(xa)) {
    const int X = px(t);
    cv::line(canvas, {X, plot.y}, {X, plot.y + plot.height}, grid, 1);
    const std::string s = tick_text(t);
    text(canvas, s, cv::Point(X - text_width(s, 0.38) / 2, plot.y + plot.height + 16), 0.38);
  }
  for (double t : ticks(ya)) {
    const int Y = py(t);
    cv::line(canvas, {plot.x, Y}, {plot.x + plot.width, Y}, grid, 1);
    const std::string s = tick_text(t);
    text(canvas, s, cv::Point(plot.x - 6 - text_width(s, 0.38), Y + 4), 0.38);
  }
  cv::rectangle(canvas, plot, black, 1);
  const std::string xlabel = xa.label + (xa.log ? " (log)" : "");
  text(canvas, xlabel, cv::Point(plot.x + (plot.width - text_width(xlabel)) / 2, plot.y + plot.height + 38));

  for (const Series& s : series) {
    cv::Point previous(-1, -1);
    for (std::size_t i = 0; i < x.size(); ++i) {
      const cv::Point p(px(x[i]), py(s.y[i]));
      if (join && previous.x >= 0) cv::line(canvas, previous, p, s.colour, 1, cv::LINE_AA);
      previous = p;
      if (s.y[i] > 0) {
        cv::circle(canvas, p, 3, s.colour, cv::FILLED, cv::LINE_AA);
      } else {
        cv::circle(canvas, p, 3, s.colour, 1, cv::LINE_AA);  // zero: hollow, on the bottom edge
      }
      if (static_cast<int>(i) == base_index) cv::circle(canvas, p, 7, black, 1, cv::LINE_AA);
    }
  }
  if (!labels.empty() && !series.empty()) {
    for (std::size_t i = 0; i < x.size(); ++i) {
      text(canvas, labels[i], cv::Point(px(x[i]) + 5, py(series.front().y[i]) - 6), 0.34, cv::Scalar(60, 60, 60));
    }
  }
}

}  // namespace

std::string sweep_csv(const SweepResult& r) {
  const std::vector<std::string> columns = {
      "knob", "value", "is_default", "status", "message", "identical_percent", "differing_codes", "codes", "max_lsb",
      "mean_lsb", "rms_lsb", "linear_max", "linear_rms", "drive_max_lsb", "residual_saturated", "residual_rounded",
      "seconds_per_frame", "min_seconds_per_frame", "reference_seconds_per_frame", "setup_seconds", "on_chip_bits",
      "off_chip_bits", "delta_on_chip_bits", "delta_off_chip_bits", "residual_format", "meets_criterion"};
  std::ostringstream s;
  const auto row = [&s](const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i) s << (i ? "," : "") << csv_field(fields[i]);
    s << "\n";
  };
  row(columns);
  for (const auto& k : r.knobs) {
    for (const auto& p : k.points) {
      std::vector<std::string> f = {k.knob->name, std::to_string(p.value), p.is_default ? "1" : "0", p.status,
                                    p.message};
      if (p.ok()) {
        for (const std::string& v :
             {general(p.identical_percent), std::to_string(p.differing), std::to_string(p.codes), general(p.max_lsb),
              general(p.mean_lsb), general(p.rms_lsb), general(p.linear_max), general(p.linear_rms),
              general(p.drive_max_lsb), std::to_string(p.residual_saturated), std::to_string(p.residual_rounded),
              general(p.seconds_per_frame), general(p.min_seconds_per_frame), general(r.reference_seconds_per_frame),
              general(p.setup_seconds), std::to_string(p.on_chip_bits), std::to_string(p.off_chip_bits),
              std::to_string(p.delta_on_chip_bits), std::to_string(p.delta_off_chip_bits), p.residual_format}) {
          f.push_back(v);
        }
      }
      f.resize(columns.size() - 1);
      f.push_back(p.meets_criterion() ? "1" : "0");
      row(f);
    }
  }
  return s.str();
}

namespace {

std::string summary_table_md(const SweepResult& r) {
  std::ostringstream s;
  s << "| knob | base | range | cheapest value meeting the criterion | identical | max | on-chip KiB | off-chip KiB "
       "| Δ memory KiB | decode ms/frame | min ms |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& k : r.knobs) {
    if (!k.skipped.empty()) continue;
    const SweepPoint* c = k.cheapest_meeting();
    s << "| `" << k.knob->name << "` | " << k.default_value << " | " << k.points.front().value << "–"
      << k.points.back().value << " | ";
    if (c) {
      s << c->value << " | " << percent_text(*c) << " | " << general(c->max_lsb) << " | " << kib(c->on_chip_bits)
        << " | " << kib(c->off_chip_bits) << " | " << signed_kib(c->delta_on_chip_bits + c->delta_off_chip_bits)
        << " | " << ms(c->seconds_per_frame) << " | " << ms(c->min_seconds_per_frame) << " |\n";
    } else {
      s << "none | | | | | | | |\n";
    }
  }
  return s.str();
}

}  // namespace

std::string sweep_markdown(const SweepResult& r) {
  std::ostringstream s;
  const auto& o = r.options;
  s << "# Fixed-point decoder: error against run time and memory\n\n";
  s << "Regenerate with `" << o.command << "`.\n\n";
  s << "* sequence: " << header_line(r) << "; every knob swept alone, the others at the base configuration "
       "(the default formats, residual " << r.base.residual_format << ")\n";
  s << "* error: output drive codes of the streaming fixed-point decoder against the double-precision reference "
       "rounded to the output depth (identical share, max / mean / RMS |Δ| in output LSB); linear light emitted "
       "from those codes by the panel model (max and RMS |Δ|); drive value v before quantisation (max |Δ|, output "
       "LSB)\n";
  s << "* time: decode wall time per view (steady clock), the median over " << o.repeats
    << " decode(s) of the sequence per view, averaged over the views (min ms: each view's fastest decode instead, "
       "the figure least disturbed by other load, plotted); the reference decoder took "
    << ms(r.reference_seconds_per_frame) << " ms per view (one decode)\n";
  s << "* memory: `FixedStreamingDecoder::report()` at " << o.hw_size.width << "x" << o.hw_size.height
    << ": on chip = line buffers + ROMs, off chip = frame stores; base " << kib(r.base.on_chip_bits) << " KiB on chip, "
    << kib(r.base.off_chip_bits) << " KiB off chip; Δ memory = on + off chip against the base\n";
  s << "* criterion (DESIGN §6): ≥ " << kReferenceAgreementCriterion.min_identical_percent()
    << " % identical codes and max |Δ| ≤ " << kReferenceAgreementCriterion.max_lsb
    << " LSB; the cheapest value meeting it is the smallest value at and above which every "
       "accepted value meets it (every knob costs the same or more as it grows, and a value that passes below a "
       "failing one is not taken)\n\n";
  s << "## Summary\n\n" << summary_table_md(r) << "\n";
  for (const auto& k : r.knobs) {
    s << "## `" << k.knob->name << "`\n\n" << k.knob->description << ". Cost: " << k.knob->cost << ".\n\n";
    if (!k.skipped.empty()) {
      s << "Skipped: " << k.skipped << ".\n\n";
      continue;
    }
    s << "![" << k.knob->name << "](sweep_" << k.knob->name << ".png)\n\n";
    s << "| value | identical | max | mean | RMS | linear max | linear RMS | drive v max | ms/frame | min ms "
         "| on-chip KiB | off-chip KiB | Δ memory KiB | meets |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& p : k.points) {
      s << "| " << value_text(p) << " | ";
      if (!p.ok()) {
        s << p.status << ": " << md_cell(p.message) << " | | | | | | | | | | | | |\n";
        continue;
      }
      s << percent_text(p) << " | " << general(p.max_lsb) << " | " << scientific(p.mean_lsb) << " | "
        << scientific(p.rms_lsb) << " | " << scientific(p.linear_max) << " | " << scientific(p.linear_rms) << " | "
        << fixed_text(p.drive_max_lsb, 3) << " | " << ms(p.seconds_per_frame) << " | " << ms(p.min_seconds_per_frame)
        << " | " << kib(p.on_chip_bits) << " | "
        << kib(p.off_chip_bits) << " | " << signed_kib(p.delta_on_chip_bits + p.delta_off_chip_bits) << " | "
        << (p.meets_criterion() ? "yes" : "no") << " |\n";
    }
    s << "\n";
  }
  return s.str();
}

Json sweep_json(const SweepResult& r) {
  const auto& o = r.options;
  const auto& po = o.pipeline;
  Json j;
  j["tool"] = "trm sweep";
  j["command"] = o.command;
  j["parameters"] = {{"source", source_text(o)},
                     {"size", {r.size.width, r.size.height}},
                     {"reduced_size", {r.reduced.width, r.reduced.height}},
                     {"views", r.views},
                     {"encoder", encoder_json(po.encoder)},
                     {"output_bits", po.output_bits},
                     {"sensitivity", po.sensitivity},
                     {"panel", po.panel},
                     {"seed", po.seed},
                     {"repeats", o.repeats},
                     {"hw_size", {o.hw_size.width, o.hw_size.height}}};
  j["criterion"] = {{"identical_percent_at_least", kReferenceAgreementCriterion.min_identical_percent()},
                    {"max_lsb_at_most", kReferenceAgreementCriterion.max_lsb}};
  j["reference_seconds_per_frame"] = r.reference_seconds_per_frame;
  const auto point_json = [&](const SweepPoint& p) {
    Json pj;
    pj["value"] = p.value;
    pj["is_default"] = p.is_default;
    pj["status"] = p.status;
    if (!p.ok()) {
      pj["message"] = p.message;
      return pj;
    }
    pj["error"] = {{"codes", p.codes},
                   {"differing_codes", p.differing},
                   {"identical_percent", p.identical_percent},
                   {"max_lsb", p.max_lsb},
                   {"mean_lsb", p.mean_lsb},
                   {"rms_lsb", p.rms_lsb},
                   {"linear_max", p.linear_max},
                   {"linear_rms", p.linear_rms},
                   {"drive_max_lsb", p.drive_max_lsb}};
    pj["residual_events"] = {{"saturated", p.residual_saturated}, {"rounded", p.residual_rounded}};
    pj["time"] = {{"seconds_per_frame", p.seconds_per_frame},
                  {"min_seconds_per_frame", p.min_seconds_per_frame},
                  {"repeat_seconds_per_frame", p.repeat_seconds_per_frame},
                  {"setup_seconds", p.setup_seconds}};
    pj["memory"] = {{"on_chip_bits", p.on_chip_bits},
                    {"off_chip_bits", p.off_chip_bits},
                    {"delta_on_chip_bits", p.delta_on_chip_bits},
                    {"delta_off_chip_bits", p.delta_off_chip_bits}};
    pj["residual_format"] = p.residual_format;
    pj["meets_criterion"] = p.meets_criterion();
    return pj;
  };
  j["base"] = point_json(r.base);
  Json knobs = Json::array();
  for (const auto& k : r.knobs) {
    Json kj;
    kj["name"] = k.knob->name;
    kj["description"] = k.knob->description;
    kj["cost"] = k.knob->cost;
    kj["base_value"] = k.default_value;
    if (!k.skipped.empty()) {
      kj["skipped"] = k.skipped;
    } else {
      const SweepPoint* c = k.cheapest_meeting();
      kj["cheapest_meeting_criterion"] = c ? Json(c->value) : Json(nullptr);
      Json points = Json::array();
      for (const auto& p : k.points) points.push_back(point_json(p));
      kj["points"] = std::move(points);
    }
    knobs.push_back(std::move(kj));
  }
  j["knobs"] = std::move(knobs);
  j["wall_seconds"] = r.wall_seconds;
  return j;
}

cv::Mat sweep_plot(const SweepResult& r, const SweepKnobResult& k) {
  const int panel_w = 540, panel_h = 440, top = 56;
  cv::Mat canvas(top + panel_h, 3 * panel_w, CV_8UC3, cv::Scalar(255, 255, 255));
  std::vector<const SweepPoint*> points;
  for (const auto& p : k.points) {
    if (p.ok()) points.push_back(&p);
  }
  std::string title = k.knob->name;
  title.append(": ").append(k.knob->description);
  text(canvas, title, cv::Point(10, 20), 0.5);
  std::string subtitle = header_line(r);
  subtitle.append("; memory at ").append(std::to_string(r.options.hw_size.width)).append("x").append(
      std::to_string(r.options.hw_size.height));
  const int rejected = static_cast<int>(k.points.size() - points.size());
  if (rejected > 0) subtitle.append("; ").append(std::to_string(rejected)).append(" value(s) rejected, not drawn");
  text(canvas, subtitle, cv::Point(10, 38), 0.4, cv::Scalar(70, 70, 70));
  // Legend.
  const std::vector<std::pair<std::string, cv::Scalar>> legend = {
      {"max |d|", cv::Scalar(200, 30, 30)},
      {"RMS |d|", cv::Scalar(30, 140, 40)},
      {"mean |d|", cv::Scalar(30, 70, 200)}};
  int lx = 3 * panel_w - 420;
  for (const auto& [label, colour] : legend) {
    cv::circle(canvas, cv::Point(lx, 50), 4, colour, cv::FILLED, cv::LINE_AA);
    text(canvas, label, cv::Point(lx + 8, 54), 0.4);
    lx += 90;
  }
  cv::circle(canvas, cv::Point(lx, 50), 7, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  text(canvas, "base value", cv::Point(lx + 10, 54), 0.4);
  if (points.empty()) {
    text(canvas, "no value of this knob was accepted", cv::Point(20, top + 60), 0.6);
    return canvas;
  }

  std::vector<double> x_value, x_memory, x_time;
  std::vector<Series> series = {{"max", cv::Scalar(200, 30, 30), {}},
                                {"rms", cv::Scalar(30, 140, 40), {}},
                                {"mean", cv::Scalar(30, 70, 200), {}}};
  std::vector<std::string> labels;
  int base_index = -1;
  bool on_varies = false, off_varies = false;
  for (const SweepPoint* p : points) {
    on_varies = on_varies || p->on_chip_bits != points.front()->on_chip_bits;
    off_varies = off_varies || p->off_chip_bits != points.front()->off_chip_bits;
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const SweepPoint& p = *points[i];
    if (p.is_default) base_index = static_cast<int>(i);
    x_value.push_back(p.value);
    const std::int64_t bits = off_varies && on_varies ? p.on_chip_bits + p.off_chip_bits
                              : off_varies            ? p.off_chip_bits
                                                      : p.on_chip_bits;
    x_memory.push_back(static_cast<double>(bits) / 8.0 / 1024.0);
    x_time.push_back(p.min_seconds_per_frame * 1e3);
    series[0].y.push_back(p.max_lsb);
    series[1].y.push_back(p.rms_lsb);
    series[2].y.push_back(p.mean_lsb);
    labels.push_back(std::to_string(p.value));
  }
  const Axis ya = error_axis({series[0].y, series[1].y, series[2].y});
  const std::string memory_label = on_varies && off_varies ? "on + off chip memory (KiB)"
                                   : off_varies            ? "off-chip memory (KiB)"
                                                           : "on-chip memory (KiB)";
  draw_panel(canvas, cv::Rect(0, top, panel_w, panel_h), "error vs knob value",
             make_axis(x_value, true, k.knob->name), x_value, ya, series, base_index, true, {});
  draw_panel(canvas, cv::Rect(panel_w, top, panel_w, panel_h),
             on_varies || off_varies ? "error vs memory" : "error vs memory (unchanged by this knob)",
             make_axis(x_memory, true, memory_label), x_memory, ya, series, base_index, true, labels);
  draw_panel(canvas, cv::Rect(2 * panel_w, top, panel_w, panel_h), "error vs decode time",
             make_axis(x_time, true, "decode time per view, ms (fastest of the repeats)"), x_time, ya, series,
             base_index, false, labels);
  return canvas;
}

std::string sweep_summary(const SweepResult& r) {
  std::ostringstream s;
  s << "  " << header_line(r) << "\n  reference " << ms(r.reference_seconds_per_frame) << " ms/view; base "
    << percent_text(r.base) << " identical, max " << general(r.base.max_lsb) << " LSB, "
    << ms(r.base.seconds_per_frame) << " ms/view, " << kib(r.base.on_chip_bits) << " KiB on / "
    << kib(r.base.off_chip_bits) << " KiB off chip at " << r.options.hw_size.width << "x" << r.options.hw_size.height
    << "\n  cheapest value with >= " << kReferenceAgreementCriterion.min_identical_percent()
    << " % identical and max <= " << kReferenceAgreementCriterion.max_lsb << " LSB:\n";
  s << "  " << std::left << std::setw(30) << "knob" << std::right << std::setw(6) << "base" << std::setw(10)
    << "cheapest" << std::setw(12) << "identical" << std::setw(5) << "max" << std::setw(11) << "on KiB"
    << std::setw(11) << "off KiB" << std::setw(10) << "d KiB" << std::setw(10) << "ms/view" << std::setw(9) << "min ms"
    << "\n";
  for (const auto& k : r.knobs) {
    s << "  " << std::left << std::setw(30) << k.knob->name << std::right << std::setw(6) << k.default_value;
    if (!k.skipped.empty()) {
      s << "   skipped: " << k.skipped << "\n";
      continue;
    }
    const SweepPoint* c = k.cheapest_meeting();
    if (!c) {
      s << std::setw(10) << "none" << "\n";
      continue;
    }
    std::string delta = signed_kib(c->delta_on_chip_bits + c->delta_off_chip_bits);
    if (delta.rfind("−", 0) == 0) delta = std::string("-").append(delta.substr(std::string("−").size()));
    s << std::setw(10) << c->value << std::setw(12) << percent_text(*c) << std::setw(5) << general(c->max_lsb)
      << std::setw(11) << kib(c->on_chip_bits) << std::setw(11) << kib(c->off_chip_bits) << std::setw(10) << delta
      << std::setw(10) << ms(c->seconds_per_frame) << std::setw(9) << ms(c->min_seconds_per_frame) << "\n";
  }
  return s.str();
}

}  // namespace trm::cli
