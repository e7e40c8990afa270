// `trm sweep` (DESIGN §7, error against run time): every approximation knob of the fixed-point decoder swept alone
// around the base configuration (the default formats plus the shared options), each point decoding the same encoded
// sequence with the streaming decoder and held to the double-precision reference: output-code and linear-light error,
// decode time per frame, and the on-chip / off-chip memory of FixedStreamingDecoder::report(). The points are
// written out by sweep_report.hpp.
#pragma once

#include "pipeline.hpp"

#include "trm/fixed_decoder.hpp"
#include "trm/metrics.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace trm::cli {

using Json = nlohmann::ordered_json;

// One approximation knob: an integer field (or derived width) of FixedDecoderConfig.
struct SweepKnob {
  std::string name;         // as --knob takes it, e.g. "residual_bits"
  std::string description;  // what it sets
  std::string cost;         // where it costs: "off chip", "on chip (ROM)", "arithmetic width only", ...
  std::vector<int> values;  // the default sweep range (the base value is always added)
  bool oled = true;         // used with an OLED panel
  bool lcd = true;          // used with the LCD panel
  bool linear_space_only = false;  // used when D and U act in linear light (--resample-space linear) only
  std::function<int(const FixedDecoderConfig&)> get;
  // Sets the knob on a copy of the base configuration; may throw std::invalid_argument (the point is rejected).
  std::function<void(FixedDecoderConfig&, int)> set;
};

// Every knob, in pipeline order.
const std::vector<SweepKnob>& sweep_knobs();
// The knob called name, or nullptr.
const SweepKnob* find_sweep_knob(const std::string& name);

// Which part of the sweep's points one process evaluates (`--shard K/N`, sweep_shard.hpp): the points are numbered
// in sweep order, the base point first, and shard K takes those whose number is K - 1 modulo N.
struct SweepShard {
  int index = 1;  // K, 1-based
  int count = 1;  // N
  bool whole() const { return count == 1; }
  bool owns(std::int64_t point_number) const { return point_number % count == index - 1; }
};

struct SweepOptions {
  PipelineOptions pipeline;           // scene / input, size, frames, r, panel, bits, ...; impl is ignored
  std::vector<std::string> knobs;     // empty: every knob the panel uses
  std::vector<int> values;            // replaces the default range (only with exactly one knob)
  int repeats = 5;                    // decode time: median per view over this many decodes of the sequence
  cv::Size hw_size{1080, 1200};       // view size the memory figures are reported for
  std::string command;                // the command line that reproduces the run (for the reports)
  SweepShard shard;                   // the whole sweep unless --shard

  // Throws std::invalid_argument with one clear message: unknown knob (listing the known ones), --values without
  // exactly one knob, repeats < 1, a shard count above the number of points, and everything
  // PipelineOptions::validate() rejects.
  void validate() const;
};

struct SweepPoint {
  int value = 0;
  bool is_default = false;
  std::string status = "ok";          // ok | rejected (validate() refused the configuration) | failed (decode threw)
  std::string message;                // why, when not ok
  // Output drive codes against the reference's, rounded to the output depth.
  std::int64_t codes = 0;
  std::int64_t differing = 0;
  double identical_percent = 0.0;
  double max_lsb = 0.0;
  double mean_lsb = 0.0;
  double rms_lsb = 0.0;
  // Emitted linear light (panel model of the quantised drive) against the reference's.
  double linear_max = 0.0;
  double linear_rms = 0.0;
  // Drive value v before output quantisation (DecodedFrame::drive), in output LSB.
  double drive_max_lsb = 0.0;
  std::uint64_t residual_saturated = 0;  // rho samples saturated / rounded by the residual store, all frames
  std::uint64_t residual_rounded = 0;
  // Run time: decode wall seconds per view (each view's median over the repeats, averaged over the views), each
  // repeat's figure, and construction (ROMs).
  double seconds_per_frame = 0.0;
  double min_seconds_per_frame = 0.0;  // the same with each view's fastest decode (least disturbed by other load)
  std::vector<double> repeat_seconds_per_frame;
  double setup_seconds = 0.0;
  // Memory at SweepOptions::hw_size: line buffers + ROMs, frame stores, and the change against the base point.
  std::int64_t on_chip_bits = 0;
  std::int64_t off_chip_bits = 0;
  std::int64_t delta_on_chip_bits = 0;
  std::int64_t delta_off_chip_bits = 0;
  std::string residual_format;        // the residual store of this point (it follows linear_frac_bits)

  bool ok() const { return status == "ok"; }
  bool meets_criterion() const {
    return ok() && kReferenceAgreementCriterion.met_by(codes - differing, codes, max_lsb);
  }
};

// A part file holds its points as JSON (sweep_shard.cpp); every field is carried, so a merged sweep writes what a
// single run writes.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(SweepPoint, value, is_default, status, message, codes, differing,
                                   identical_percent, max_lsb, mean_lsb, rms_lsb, linear_max, linear_rms,
                                   drive_max_lsb, residual_saturated, residual_rounded, seconds_per_frame,
                                   min_seconds_per_frame, repeat_seconds_per_frame, setup_seconds, on_chip_bits,
                                   off_chip_bits, delta_on_chip_bits, delta_off_chip_bits, residual_format)

struct SweepKnobResult {
  const SweepKnob* knob = nullptr;
  int default_value = 0;
  std::string skipped;                // non-empty: the knob does not apply (the reason)
  std::vector<SweepPoint> points;     // ascending value
  // The smallest value at and above which every accepted point meets the criterion (nullptr: the most precise
  // accepted value fails it). Every knob costs the same or more as it grows.
  const SweepPoint* cheapest_meeting() const;
};

struct SweepResult {
  SweepOptions options;
  cv::Size size;                      // decoded view size
  cv::Size reduced;
  std::int64_t views = 0;             // decoded views per point
  double reference_seconds_per_frame = 0.0;
  SweepPoint base;                    // every knob at its base value
  std::vector<SweepKnobResult> knobs;
  double wall_seconds = 0.0;
  std::uint64_t recording_hash = 0;   // of the sent codes and the reference's drive codes: parts must agree on it
};

// The sweep's plan: every chosen knob in pipeline order, why it is skipped (empty: it applies) and the values it
// takes, ascending, base value included.
struct SweepPlanKnob {
  const SweepKnob* knob = nullptr;
  int default_value = 0;
  std::string skipped;
  std::vector<int> values;
};
std::vector<SweepPlanKnob> plan_sweep(const SweepOptions& options);
// The points of a plan, numbered as SweepShard numbers them: the base point (0), then every value other than the
// base of every knob that applies, in plan order.
std::int64_t sweep_point_count(const std::vector<SweepPlanKnob>& plan);

// The last step of a sweep, of a whole run and of a merge of its parts alike: adds the base point as every knob's
// base value, orders the points by value, sets the memory change against the base, and throws
// std::invalid_argument when every value asked for with --values was rejected.
void finish_sweep(SweepResult& result);

// Encodes the sequence once, decodes it once with the reference, then once per sweep point (repeats times) with
// FixedStreamingDecoder. progress(done, total) is called after every decode of the sequence. With a shard other
// than the whole, only its points are decoded and the result is left unfinished: the base point is there only
// in the shard that owns it, and no knob holds its base value (finish_sweep() adds them once the parts are merged).
SweepResult run_sweep(const SweepOptions& options,
                      const std::function<void(std::int64_t done, std::int64_t total)>& progress = {});

}  // namespace trm::cli
