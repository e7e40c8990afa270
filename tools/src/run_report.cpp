#include "run_report.hpp"

#include "trm/decoder_json.hpp"
#include "trm/resample.hpp"
#include "trm/transfer.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace trm::cli {

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Saturation / clip events of the fixed-point decoder, per stage, and its DESIGN §7 skip events (output lines).
Json events_json(const FixedStageCounts& c) {
  Json j = {{"beta_clipped", c.beta_clipped},         {"residual_saturated", c.residual_saturated},
            {"residual_rounded", c.residual_rounded}, {"alpha_clipped", c.alpha_clipped},
            {"weight_underflow", c.weight_underflow}, {"lcd_unreachable", c.lcd_unreachable}};
  j["skipped"] = {{"motion_test_lines", c.motion_test_lines_skipped},
                  {"residual_read_lines", c.residual_read_lines_skipped},
                  {"residual_write_lines", c.residual_write_lines_skipped},
                  {"grey_lines_one_channel", c.grey_lines},
                  {"grey_reduced_rows_one_channel", c.grey_reduced_rows}};
  return j;
}

Json json_number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// The off-chip traffic the skips saved, in bytes (skip_traffic_saved).
Json traffic_json(const FixedSkipTraffic& t) {
  const auto bytes = [](std::int64_t bits) { return static_cast<double>(bits) / 8.0; };
  return {{"residual_write", bytes(t.residual_write_bits)},
          {"residual_read", bytes(t.residual_read_bits)},
          {"previous_low_read", bytes(t.previous_low_read_bits)},
          {"lcd_stores", bytes(t.lcd_store_bits)},
          {"total", bytes(t.total_bits())}};
}

}  // namespace

cv::Mat preview_8bit(const cv::Mat& linear_rgb) {
  cv::Mat out;
  quantise(to_encoded(linear_rgb, Transfer::Srgb), 8).convertTo(out, CV_8U);
  return out;
}

std::int64_t payload_bytes(const FrameMeta& meta) {
  const std::int64_t bits = static_cast<std::int64_t>(meta.width) * meta.height * 3 * meta.bits;
  return (bits + 7) / 8;
}

JsonLinesWriter::JsonLinesWriter(const std::filesystem::path& path) : path_(path), file_(path) {}

void JsonLinesWriter::write(const Json& record) { file_.write(record.dump() + "\n"); }

void JsonLinesWriter::close() { file_.commit(); }

RunRecorder::RunRecorder(const PipelineOptions& options, const std::filesystem::path& directory)
    : options_(options),
      panel_(options.panel),
      full_rate_(options.panel, options.output_bits),
      pairs_tracker_(options.panel),
      view_records_(directory / "views.jsonl"),
      pair_records_(directory / "pairs.jsonl") {}

void RunRecorder::close() {
  view_records_.close();
  pair_records_.close();
}

cv::Mat RunRecorder::add(const DecodedView& view) {
  const DecodedFrame& d = *view.decoded;
  const FrameMeta& meta = view.slot;
  full_width_ = meta.full_width;
  full_height_ = meta.full_height;
  FrameMeta full_meta = meta;
  full_meta.width = meta.full_width;
  full_meta.height = meta.full_height;
  const std::int64_t bytes = view.sent ? payload_bytes(meta) : 0;
  const std::int64_t full_pixels = static_cast<std::int64_t>(meta.full_width) * meta.full_height;
  sum_payload_ += static_cast<double>(bytes);
  sum_full_payload_ += static_cast<double>(payload_bytes(full_meta));
  sum_pixels_rendered_ += static_cast<double>(view.pixels_rendered);
  sum_pixels_sent_ += view.sent ? static_cast<double>(view.sent->codes.total()) : 0.0;
  sum_pixels_full_ += static_cast<double>(full_pixels);
  if (meta.parity == Parity::Reduced) {
    if (view.sent) {
      reduced_width_ = meta.width;
      reduced_height_ = meta.height;
    }
  } else {
    ++full_views_;
    sum_clipped_full_ += d.stats.clipped_fraction;
  }
  max_residual_ = std::max(max_residual_, d.stats.residual_max_abs);
  sum_encode_ += view.encode_seconds;
  sum_decode_ += view.decode_seconds;

  Json rec;
  rec["t"] = meta.index;
  rec["eye"] = meta.eye;
  rec["parity"] = to_string(meta.parity);
  rec["sent"] = view.sent != nullptr;
  rec["sent_size"] = view.sent ? Json::array({meta.width, meta.height}) : Json::array({0, 0});
  rec["pixels_rendered"] = view.pixels_rendered;
  rec["payload_bytes"] = bytes;
  rec["clipped_fraction"] = d.stats.clipped_fraction;
  rec["residual_mean_abs"] = d.stats.residual_mean_abs;
  rec["residual_max_abs"] = d.stats.residual_max_abs;
  if (meta.parity == Parity::Reduced) {
    rec["residual_applied"] = d.stats.residual_applied;
    rec["mean_motion_weight"] = d.stats.mean_motion_weight;
    rec["dropped_sum"] = d.stats.dropped_sum;
  }
  if (panel_.has_history()) rec["lcd_unreachable_fraction"] = d.stats.lcd_unreachable_fraction;
  if (view.fixed_counts) {
    const FixedStageCounts& c = *view.fixed_counts;
    rec["fixed_point_events"] = events_json(c);
    fixed_totals_ += c;
    if (meta.parity == Parity::Reduced && d.stats.residual_applied) skip_lines_reduced_ += meta.full_height;
    if (meta.parity == Parity::Full) skip_lines_full_ += meta.full_height;
    skip_lines_all_ += meta.full_height;
    have_fixed_counts_ = true;
    ++fixed_views_;
  }
  if (view.reference) {
    const CodeAgreement agreement = compare_codes(d.drive_codes, view.reference->drive_codes);
    vs_reference_ += agreement;
    rec["vs_reference"] = {{"identical_fraction", agreement.identical_fraction()}, {"max_lsb", agreement.max_lsb}};
    if (panel_.has_history()) rec["vs_reference"]["panel_history"] = "synchronised";
  }
  if (view.free_running_reference) {
    const CodeAgreement agreement = compare_codes(d.drive_codes, view.free_running_reference->drive_codes);
    vs_free_running_ += agreement;
    const double merge_codes = max_merge_difference_codes(
        d.emitted_linear, view.free_running_reference->emitted_linear, panel_.lcd, options_.output_bits);
    max_free_running_merge_codes_ = std::max(max_free_running_merge_codes_, merge_codes);
    rec["vs_free_running_reference"] = {{"identical_fraction", agreement.identical_fraction()},
                                        {"max_lsb", agreement.max_lsb},
                                        {"max_merge_difference_codes", merge_codes}};
  }
  rec["seconds"] = {{"render", view.render_seconds}, {"encode", view.encode_seconds}, {"decode", view.decode_seconds}};
  sum_render_ += view.render_seconds;
  view_records_.write(rec);
  ++views_;

  const cv::Mat reference = full_rate_(*view.linear_full);
  cv::Mat perceived;
  if (const auto pair = pairs_tracker_.add(meta.eye, meta.index, d.emitted_linear, reference)) {
    perceived = pair->perceived;
    last_reference_pair_ = pair->reference;
    const double psnr = psnr_srgb(perceived, last_reference_pair_);
    const double max_abs = cv::norm(perceived, last_reference_pair_, cv::NORM_INF);
    Json record;
    record["t"] = {pair->first, meta.index};
    record["eye"] = meta.eye;
    record["psnr_db"] = json_number(psnr);
    record["max_abs_linear"] = max_abs;
    pair_records_.write(record);
    ++pairs_;
    if (std::isfinite(psnr)) {
      sum_psnr_ += psnr;
      min_psnr_ = std::min(min_psnr_, psnr);
      ++finite_psnr_pairs_;
    } else {
      ++exact_pairs_;
    }
  }
  return perceived;
}

Json RunRecorder::report(double wall_seconds) const {
  Json r;
  r["tool"] = "trm";
  Json p;
  p["source"] = options_.input.empty() ? options_.scene : options_.input;
  p["size"] = {full_width_, full_height_};
  p["reduced_size"] = {reduced_width_, reduced_height_};
  p["refresh_hz"] = options_.refresh_hz;
  // The headset side's whole configuration: the fixed-point formats too where a fixed-point decoder ran.
  const FixedDecoderConfig decoder = fixed_config_of(options_);
  p["decoder"] = options_.method_impl() == "reference" ? decoder_json(decoder.decoder) : fixed_decoder_json(decoder);
  p["method"] = options_.method;
  p["impl"] = options_.method_impl();
  p["seed"] = options_.seed;
  r["parameters"] = p;

  Json s;
  const auto n = static_cast<double>(views_);
  s["views"] = views_;
  s["pixel_ratio"] = sum_full_payload_ > 0 ? sum_payload_ / sum_full_payload_ : 0.0;
  // Per frame pair against full rate (2 W H each): what the GPU rendered and what the link carried.
  s["pixels_rendered_ratio"] = sum_pixels_full_ > 0 ? sum_pixels_rendered_ / sum_pixels_full_ : 0.0;
  s["pixels_sent_ratio"] = sum_pixels_full_ > 0 ? sum_pixels_sent_ / sum_pixels_full_ : 0.0;
  // Per pair of one eye's views (two view slots).
  s["pixels_rendered_per_pair"] = views_ > 0 ? 2.0 * sum_pixels_rendered_ / n : 0.0;
  s["pixels_sent_per_pair"] = views_ > 0 ? 2.0 * sum_pixels_sent_ / n : 0.0;
  s["payload_bytes_total"] = sum_payload_;
  s["mean_clipped_fraction_full"] = full_views_ ? sum_clipped_full_ / static_cast<double>(full_views_) : 0.0;
  s["max_residual_abs"] = max_residual_;
  s["pairs"] = pairs_;
  s["pairs_exact"] = exact_pairs_;
  s["mean_psnr_db"] = finite_psnr_pairs_ ? json_number(sum_psnr_ / static_cast<double>(finite_psnr_pairs_)) : Json(nullptr);
  s["min_psnr_db"] = finite_psnr_pairs_ ? json_number(min_psnr_) : Json(nullptr);
  if (vs_reference_.compared > 0) {
    s["vs_reference"] = {{"codes_compared", vs_reference_.compared},
                         {"identical_fraction", vs_reference_.identical_fraction()},
                         {"max_lsb", vs_reference_.max_lsb},
                         {"meets_criterion", kReferenceAgreementCriterion.met_by(vs_reference_)}};
    if (panel_.has_history()) s["vs_reference"]["panel_history"] = "synchronised";
  }
  if (vs_free_running_.compared > 0) {
    s["vs_free_running_reference"] = {{"codes_compared", vs_free_running_.compared},
                                      {"identical_fraction", vs_free_running_.identical_fraction()},
                                      {"max_lsb", vs_free_running_.max_lsb},
                                      {"max_merge_difference_codes", max_free_running_merge_codes_}};
  }
  if (have_fixed_counts_) {
    s["fixed_point_events"] = events_json(fixed_totals_);
    s["fixed_point_events"]["traffic_saved_bytes"] = traffic_json(skip_traffic());
  }
  s["mean_seconds"] = {{"render", n > 0 ? sum_render_ / n : 0.0},
                       {"encode", n > 0 ? sum_encode_ / n : 0.0},
                       {"decode", n > 0 ? sum_decode_ / n : 0.0}};
  s["wall_seconds"] = wall_seconds;
  r["summary"] = s;
  r["records"] = {{"views", view_records_.file_name()}, {"pairs", pair_records_.file_name()}};
  return r;
}

std::string RunRecorder::summary_table() const {
  const Json s = report(0.0)["summary"];
  std::ostringstream out;
  char line[256];
  auto row = [&](const char* key, const std::string& value) {
    std::snprintf(line, sizeof line, "  %-34s %s\n", key, value.c_str());
    out << line;
  };
  auto fmt = [&](const char* f, double v) {
    char b[64];
    std::snprintf(b, sizeof b, f, v);
    return std::string(b);
  };
  row("views decoded", std::to_string(views_));
  row("full / reduced size", std::to_string(full_width_) + "x" + std::to_string(full_height_) + " / " +
                                 std::to_string(reduced_width_) + "x" + std::to_string(reduced_height_));
  row("method", options_.method);
  row("pixels rendered / sent vs full",
      fmt("%.4f", s["pixels_rendered_ratio"].get<double>()) + " / " + fmt("%.4f", s["pixels_sent_ratio"].get<double>()));
  row("link payload vs full rate", fmt("%.4f", s["pixel_ratio"].get<double>()));
  row("full frames clipped (mean)", fmt("%.3f %%", 100.0 * s["mean_clipped_fraction_full"].get<double>()));
  row("max |residual|", fmt("%.4f", max_residual_));
  std::string psnr = "n/a (no frame pair)";
  if (finite_psnr_pairs_ > 0) {
    psnr = fmt("mean %.2f dB", sum_psnr_ / static_cast<double>(finite_psnr_pairs_)) + fmt(", min %.2f dB", min_psnr_);
    if (exact_pairs_ > 0) psnr += ", " + std::to_string(exact_pairs_) + " pairs exact";
  } else if (exact_pairs_ > 0) {
    psnr = "all " + std::to_string(exact_pairs_) + " pairs exact";
  }
  row("perceived pair vs full rate (PSNR)", psnr);
  if (vs_reference_.compared > 0) {
    row(("decoder " + options_.method_impl() + " vs reference").c_str(),
        fmt("%.4f %% of codes identical", 100.0 * vs_reference_.identical_fraction()) +
            fmt(", max %.0f LSB", vs_reference_.max_lsb) +
            (panel_.has_history() ? " (panel history synchronised)" : "") +
            (kReferenceAgreementCriterion.met_by(vs_reference_) ? "; meets" : "; misses") + " DESIGN §6");
  }
  if (vs_free_running_.compared > 0) {
    row("  free-running (own LCD history)",
        fmt("%.4f %% identical", 100.0 * vs_free_running_.identical_fraction()) +
            fmt(", max %.0f LSB", vs_free_running_.max_lsb) +
            fmt(", merge M within %.3f codes", max_free_running_merge_codes_));
  }
  if (have_fixed_counts_ && options_.no_skip) {
    row("lines skipped (fixed-point)", "none: full path everywhere (--no-skip)");
  } else if (have_fixed_counts_ && (skip_lines_reduced_ > 0 || skip_lines_full_ > 0)) {
    const auto share = [&](std::uint64_t n, std::int64_t of) { return of > 0 ? 100.0 * static_cast<double>(n) / static_cast<double>(of) : 0.0; };
    row("lines skipped (fixed-point)",
        fmt("motion test %.1f %%", share(fixed_totals_.motion_test_lines_skipped, skip_lines_reduced_)) +
            fmt(", residual read %.1f %%", share(fixed_totals_.residual_read_lines_skipped, skip_lines_reduced_)) +
            fmt(", residual write %.1f %%", share(fixed_totals_.residual_write_lines_skipped, skip_lines_full_)) +
            fmt(", grey (one channel) %.1f %%", share(fixed_totals_.grey_lines, skip_lines_all_)));
  }
  if (have_fixed_counts_) {
    const FixedSkipTraffic t = skip_traffic();
    const double per_view = 1.0 / (8.0 * 1024.0 * static_cast<double>(fixed_views_));
    if (t.total_bits() > 0) {
      row("off-chip traffic saved per view",
          fmt("%.1f kB", static_cast<double>(t.total_bits()) * per_view) +
              fmt(" (residual write %.1f", static_cast<double>(t.residual_write_bits) * per_view) +
              fmt(", read %.1f", static_cast<double>(t.residual_read_bits) * per_view) +
              fmt(", d_{t-1} read %.1f", static_cast<double>(t.previous_low_read_bits) * per_view) +
              fmt(", LCD stores %.1f)", static_cast<double>(t.lcd_store_bits) * per_view));
    }
  }
  if (have_fixed_counts_ && fixed_totals_.residual_saturated > 0) {
    row("residual store saturations", std::to_string(fixed_totals_.residual_saturated) + " samples");
  }
  row("encode / decode per view", fmt("%.1f ms", 1e3 * s["mean_seconds"]["encode"].get<double>()) + " / " +
                                      fmt("%.1f ms", 1e3 * s["mean_seconds"]["decode"].get<double>()));
  return out.str();
}

FixedSkipTraffic RunRecorder::skip_traffic() const {
  return skip_traffic_saved(fixed_config_of(options_), cv::Size(full_width_, full_height_), fixed_totals_,
                            fixed_views_);
}

Progress::Progress(std::int64_t total) : total_(total), start_(now_seconds()), tty_(isatty(STDERR_FILENO) != 0) {}

void Progress::update(std::int64_t done) {
  const double now = now_seconds();
  const double elapsed = now - start_;
  if (elapsed < 2.0 || now - last_print_ < (tty_ ? 0.25 : 5.0)) return;
  last_print_ = now;
  printed_ = true;
  const double rate = static_cast<double>(done) / elapsed;
  const double eta = rate > 0 ? static_cast<double>(total_ - done) / rate : 0.0;
  std::fprintf(stderr, "%s[%lld/%lld] %.1f frames/s, %.0f s left%s", tty_ ? "\r" : "", static_cast<long long>(done),
               static_cast<long long>(total_), rate, eta, tty_ ? "   " : "\n");
  std::fflush(stderr);
}

void Progress::finish() {
  if (printed_ && tty_) std::fprintf(stderr, "\n");
}

}  // namespace trm::cli
