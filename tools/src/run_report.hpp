// Streams per-view records and per-pair perception figures from the pipeline to JSON Lines files, keeps running
// statistics for report.json's summary, and renders the human-readable summary table.
#pragma once

#include "trm/atomic_file.hpp"
#include "trm/metrics.hpp"

#include "pipeline.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

namespace trm::cli {

using Json = nlohmann::ordered_json;

// Linear RGB in [0, 1] -> 8-bit sRGB preview (RGB order).
cv::Mat preview_8bit(const cv::Mat& linear_rgb);

// Link payload of one view in bytes: width x height x 3 channels x bits, packed.
std::int64_t payload_bytes(const FrameMeta& meta);

// One JSON object per line, written as it comes: a long run's records live on disk, not in memory.
class JsonLinesWriter {
 public:
  explicit JsonLinesWriter(const std::filesystem::path& path);  // throws std::runtime_error naming the path
  void write(const Json& record);
  void close();  // moves the file into place; throws on an I/O failure
  std::string file_name() const { return path_.filename().string(); }

 private:
  std::filesystem::path path_;
  io::AtomicFile file_;  // the one file writer: every failure names the file and the reason
};

class RunRecorder {
 public:
  // Per-view records go to views.jsonl and per-pair records to pairs.jsonl in `directory`.
  RunRecorder(const PipelineOptions& options, const std::filesystem::path& directory);
  // Records one decoded view; returns the perceived pair (linear) when this view completes a pair
  // (frames 2k and 2k + 1 of one eye), else an empty Mat.
  cv::Mat add(const DecodedView& view);
  // The full-rate reference of the most recently completed pair (linear): the panel showing every
  // frame at full resolution, through the same drive quantisation.
  const cv::Mat& last_reference_pair() const { return last_reference_pair_; }

  // Closes the record files (call before report()).
  void close();
  // Parameters, summary and "records": the names of the record files.
  Json report(double wall_seconds) const;
  std::string summary_table() const;
  std::int64_t views() const { return views_; }
  int full_width() const { return full_width_; }
  int full_height() const { return full_height_; }

 private:
  // What the skips of the views so far saved in off-chip traffic (only with fixed-point counters).
  FixedSkipTraffic skip_traffic() const;

  PipelineOptions options_;
  Panel panel_;
  FullRateEmission full_rate_;  // each view's full-rate reference
  PairTracker pairs_tracker_;
  JsonLinesWriter view_records_;
  JsonLinesWriter pair_records_;
  std::int64_t views_ = 0, pairs_ = 0;
  cv::Mat last_reference_pair_;
  int full_width_ = 0, full_height_ = 0, reduced_width_ = 0, reduced_height_ = 0;
  double sum_full_payload_ = 0, sum_payload_ = 0;
  double sum_clipped_full_ = 0, max_residual_ = 0, sum_encode_ = 0, sum_decode_ = 0;
  std::int64_t full_views_ = 0;
  double sum_psnr_ = 0, min_psnr_ = 1e300;
  std::int64_t finite_psnr_pairs_ = 0, exact_pairs_ = 0;
  // Fixed-point decoder against the reference beside it: output codes compared.
  CodeAgreement vs_reference_;
  CodeAgreement vs_free_running_;  // LCD only
  double max_free_running_merge_codes_ = 0.0;  // max |M_fixed - M_reference| in drive codes
  FixedStageCounts fixed_totals_;
  std::int64_t skip_lines_reduced_ = 0;  // output lines of reduced views with a residual (motion / residual-read skips)
  std::int64_t skip_lines_full_ = 0;     // output lines of full views (residual-write skips)
  std::int64_t skip_lines_all_ = 0;      // output lines of every view (grey skips)
  bool have_fixed_counts_ = false;
  std::int64_t fixed_views_ = 0;  // views with fixed-point counters (fixed_totals_ sums them)
  double sum_render_ = 0;
  double sum_pixels_rendered_ = 0, sum_pixels_sent_ = 0, sum_pixels_full_ = 0;
};

// Prints a progress line to stderr once the run has taken more than two seconds.
class Progress {
 public:
  explicit Progress(std::int64_t total);
  void update(std::int64_t done);
  void finish();

 private:
  std::int64_t total_;
  double start_;
  double last_print_ = 0;
  bool printed_ = false;
  bool tty_;
};

}  // namespace trm::cli
