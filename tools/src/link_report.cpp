#include "link_report.hpp"

#include "trm/plot.hpp"
#include "trm/resample.hpp"

#include <algorithm>
#include <cstdio>

namespace trm::cli {

namespace {

// Wire bits per link frame that a configuration would need, predicted from the frame geometry alone
// (raw coding): a comparison series of the plot.
link::PlotTrace predicted_trace(std::string label, const PipelineOptions& options,
                                const link::PacketizerConfig& packetizer, std::int64_t frames, int full_width,
                                int full_height, bool stereo, bool trm) {
  EncoderConfig config = options.encoder;
  config.stereo = stereo;
  const int reduced_width = reduced_size(full_width, config.reduction);
  const int reduced_height = reduced_size(full_height, config.reduction);
  link::PlotTrace trace(std::move(label));
  for (std::int64_t t = 0; t < frames; ++t) {
    double total = 0;
    for (int eye = 0; eye < (stereo ? 2 : 1); ++eye) {
      FrameMeta meta;
      meta.index = t;
      meta.eye = eye;
      meta.parity = trm ? parity_of(t, eye, config) : Parity::Full;
      meta.full_width = full_width;
      meta.full_height = full_height;
      meta.width = meta.parity == Parity::Full ? full_width : reduced_width;
      meta.height = meta.parity == Parity::Full ? full_height : reduced_height;
      meta.bits = config.bits;
      meta.transfer = config.transfer;
      total += static_cast<double>(link::predict_raw_view_bits(meta, packetizer).wire_bits());
    }
    trace.add(total);
  }
  return trace;
}

// A trace as a line in Mbit: a bucket of one value is that value; a wider one goes from its first value through its
// min..max span (at its middle) to its last, which over a bucket well under a pixel wide draws what every value would.
plot::Series mbit_series(const link::PlotTrace& trace, int colour) {
  plot::Series s{.label = trace.label(), .colour = colour};
  const auto add = [&s](double frame, double bits) {
    s.x.push_back(frame);
    s.y.push_back(bits / 1e6);
  };
  const std::int64_t width = trace.bucket_width(), count = trace.count();
  for (std::size_t k = 0; k < trace.buckets().size(); ++k) {
    const link::PlotTrace::Bucket& b = trace.buckets()[k];
    const auto first = static_cast<std::int64_t>(k) * width;
    const std::int64_t last = std::min(first + width, count) - 1;
    add(static_cast<double>(first), b.first);
    if (last == first) continue;
    if (b.min <= b.max) {
      add(0.5 * static_cast<double>(first + last), b.min);
      add(0.5 * static_cast<double>(first + last), b.max);
    }
    add(static_cast<double>(last), b.last);
  }
  return s;
}

void write_bits_plot(const std::filesystem::path& path, const std::vector<link::PlotTrace>& traces,
                     double capacity_bits, std::string title) {
  plot::Figure figure;
  figure.title = std::move(title);
  plot::Chart chart;
  chart.x = {.label = "link frame", .min = 0.0};
  chart.y = {.label = "Mbit per link frame", .min = 0.0};
  std::int64_t frames = 0;
  for (std::size_t i = 0; i < traces.size(); ++i) {
    if (traces[i].count() == 0) continue;
    chart.series.push_back(mbit_series(traces[i], static_cast<int>(i)));
    frames = std::max(frames, traces[i].count());
  }
  if (chart.series.empty()) chart.note = "no link frame was carried";
  if (capacity_bits > 0 && frames > 0) {
    const double end = static_cast<double>(std::max<std::int64_t>(frames - 1, 1));
    chart.series.push_back({.label = "link capacity per frame",
                            .x = {0.0, end},
                            .y = {capacity_bits / 1e6, capacity_bits / 1e6},
                            .dashed = true,
                            .colour = 3});
  }
  figure.charts = {std::move(chart)};
  plot::write_png(path, figure);
}

}  // namespace

LinkRecorder::LinkRecorder(const OutputDir& dir, const PipelineOptions& options)
    : dir_(dir),
      options_(options),
      csv_(dir.file("frames.csv"), options.refresh_hz, options.method),
      measured_(options.method + (options.encoder.stereo ? " stereo" : " mono") + " (this run)") {}

void LinkRecorder::add(const link::LinkFrameUsage& usage) {
  csv_.add(usage);
  measured_.add(static_cast<double>(usage.bits.wire_bits()));
}

Json LinkRecorder::finish(const LinkOutcome& outcome, int full_width, int full_height) {
  csv_.close();
  const bool stereo = options_.encoder.stereo;
  const std::int64_t frames = measured_.count();
  link::PacketizerConfig raw = options_.link_config(full_width, full_height).packetizer;
  raw.coding = link::PayloadCoding::Raw;
  const std::vector<link::PlotTrace> series = {
      measured_,
      predicted_trace(std::string("full rate ") + (stereo ? "stereo" : "mono"), options_, raw, frames, full_width,
                      full_height, stereo, false),
      predicted_trace(std::string("TRM ") + (stereo ? "mono" : "stereo off-phase") + " (raw, predicted)", options_, raw,
                      frames, full_width, full_height, !stereo, true)};
  write_bits_plot(dir_.file("link_bits.png"), series, outcome.budget.capacity_bits_per_frame(),
                  "wire bits per link frame on " + outcome.budget.preset.name);

  const link::BandwidthSummary& s = outcome.summary;
  Json j;
  j["method"] = options_.method;
  j["preset"] = outcome.budget.preset.name;
  j["description"] = outcome.budget.preset.description;
  j["data_gbps"] = outcome.budget.preset.data_gbps();
  j["cvt_rb_v2_blanking"] = outcome.budget.blanking.has_value();
  j["capacity_bits_per_frame"] = outcome.budget.capacity_bits_per_frame();
  j["fits"] = s.fits;
  j["frames_not_fitting"] = s.frames_not_fitting;
  j["peak_wire_bits"] = s.peak_wire_bits;
  j["average_wire_bits"] = s.average_wire_bits;
  j["peak_payload_bits"] = s.peak_payload_bits;
  j["average_payload_bits"] = s.average_payload_bits;  // per link frame
  j["peak_utilisation"] = s.peak_utilisation;
  j["average_utilisation"] = s.average_utilisation;
  j["total_pixel_bits"] = s.total_pixel_bits;
  j["total_payload_bits"] = s.total_payload_bits;
  j["total_overhead_bits"] = s.total_overhead_bits;
  j["required_data_gbps"] = s.required_data_gbps;
  j["minimum_preset"] = s.minimum_preset ? Json(s.minimum_preset->name) : Json(nullptr);
  j["faults"] = {{"packets_seen", outcome.faults.packets_seen},
                 {"packets_dropped", outcome.faults.packets_dropped},
                 {"packets_damaged", outcome.faults.packets_damaged},
                 {"random_bit_errors", outcome.faults.random_bit_errors},
                 {"bursts", outcome.faults.bursts},
                 {"burst_bit_errors", outcome.faults.burst_bit_errors}};
  j["receiver"] = receiver_json(outcome.receiver);
  j["concealed_lines"] = outcome.concealed_lines;
  j["lost_views"] = outcome.lost_views;
  return j;
}

Json receiver_json(const link::ReceiverCounters& c) {
  return {{"packets_received", c.packets_received}, {"packets_accepted", c.packets_accepted},
          {"crc_failures", c.crc_failures},         {"malformed", c.malformed},
          {"inconsistent", c.inconsistent},         {"duplicates", c.duplicates},
          {"stale", c.stale}};
}

std::string link_summary_lines(const LinkOutcome& outcome) {
  const link::BandwidthSummary& s = outcome.summary;
  char line[512];
  std::string out;
  std::snprintf(line, sizeof line, "  %-34s %s (%.2f Gbit/s): %s, peak %.1f %% of a frame period\n", "link",
                outcome.budget.preset.name.c_str(), outcome.budget.preset.data_gbps(),
                s.fits ? "fits" : "DOES NOT FIT", 100.0 * s.peak_utilisation);
  out += line;
  std::snprintf(line, sizeof line, "  %-34s %.2f Gbit/s; smallest preset that fits: %s\n", "link rate needed at peak",
                s.required_data_gbps, s.minimum_preset ? s.minimum_preset->name.c_str() : "none");
  out += line;
  if (outcome.faults.packets_dropped + outcome.faults.packets_damaged > 0 || outcome.lost_views > 0) {
    std::snprintf(line, sizeof line, "  %-34s %llu dropped, %llu damaged packets; %lld lines concealed, %lld views lost\n",
                  "link faults", static_cast<unsigned long long>(outcome.faults.packets_dropped),
                  static_cast<unsigned long long>(outcome.faults.packets_damaged),
                  static_cast<long long>(outcome.concealed_lines), static_cast<long long>(outcome.lost_views));
    out += line;
  }
  return out;
}

}  // namespace trm::cli
