// `trm sweep` (DESIGN §7, error against run time): every approximation knob swept alone around the base
// configuration (the default formats plus the shared options). A decoder knob's point decodes the same encoded
// sequence with the streaming decoder and is held to the double-precision reference: output-code and linear-light
// error, the perceived sequence (sweep_perceived.hpp) against the reference's seen by the same eye, decode time per
// frame, and the on-chip / off-chip memory of FixedStreamingDecoder::report(). An eye-model knob's point watches the
// base decoder's output with the knob's value against the reference decoder's seen by the exact eye
// (kExactEyeSubsteps): perceived error and eye-model time per frame; the LCD's LC model (lc_model) is held instead
// to the same output through the reference LC at the same eye, so that its points differ in the LC alone. The
// linear-resample-space knobs sweep around a base of their own in that space when the run's space is the encoded
// one. The points are written out by sweep_report.hpp.
#pragma once

#include "pipeline.hpp"
#include "sweep_perceived.hpp"

#include "trm/fixed_decoder.hpp"
#include "trm/metrics.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace trm::cli {

using Json = nlohmann::ordered_json;

// Everything a knob can set: the fixed-point decoder and the eye model that watches its output.
struct SweepConfig {
  FixedDecoderConfig decoder;
  int eye_substeps = kDefaultRetinaSubsteps;  // RetinaOptions::substeps of the perceived sequence
};

// One approximation knob: an integer field (or derived width) of SweepConfig.
struct SweepKnob {
  std::string name;         // as --knob takes it, e.g. "residual_bits"
  std::string description;  // what it sets
  std::string cost;         // where it costs: "off chip", "on chip (ROM)", "arithmetic width only", ...
  std::vector<int> values;  // the default sweep range (the base value is always added)
  bool oled = true;         // used with an OLED panel
  bool lcd = true;          // used with the LCD panel
  bool linear_space_only = false;  // used when D and U act in linear light: swept around a linear-space base
  bool eye_model = false;          // sets the eye model, not the decoder: the base decoder's output is watched
  // An eye-model knob that sets the panel's liquid-crystal model (lc_model_names()): its points are held to the base
  // decoder's output through the reference LC (kLcModelReference) at the base eye, not to the exact eye.
  bool lc_model = false;
  // The values' names when the knob is an index (value i is value_names[i]); empty: the values are numbers.
  std::vector<std::string> value_names;
  std::function<int(const SweepConfig&)> get;
  // Sets the knob on a copy of the base configuration; may throw std::invalid_argument (the point is rejected).
  std::function<void(SweepConfig&, int)> set;

  // How the reports write `value`: its name, or the number.
  std::string value_label(int value) const;
};

// The LCD's liquid-crystal models of the eye's light, the `lc_model` knob's values: the first-order response
// (LcdPanel::lc_response) and the second-order one (lc_second_order: the preset's, or the defaults of
// LcSecondOrderParams), each without and with the panel's overdrive.
const std::vector<std::string>& lc_model_names();
// The reference every other is held to: second order with overdrive, the model with the most state (the crystal's
// level and its rate: inertia as well as viscosity) and the panel's compensation computed from that state. It is not
// a superset of the first order, whose rise τ_on depends on the drive where the second order has one τ and ζ for
// every transition: a first-order point measures another crystal as much as a coarser one.
inline constexpr int kLcModelReference = 3;
// The model of a panel's LC, and the panel with another (throws std::invalid_argument for a value outside
// lc_model_names()).
int lc_model_of(const LcdPanel& lcd);
void set_lc_model(LcdPanel& lcd, int model);

// Every knob, in pipeline order.
const std::vector<SweepKnob>& sweep_knobs();
// The knob called name, or nullptr.
const SweepKnob* find_sweep_knob(const std::string& name);

// Which part of the sweep's points one process evaluates (`--shard K/N`, sweep_shard.hpp): the points are numbered
// in sweep order, the base points first (sweep_point_count()), and shard K takes those whose number is K - 1
// modulo N.
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
  // The perceived sequence against the reference's (decoder knobs: the same eye; eye-model knobs: the exact eye).
  double perceived_psnr_db = 0.0;         // +inf: identical
  double visual_difference = 0.0;
  // Eye-model wall seconds per frame watched (eye-model knobs: the fastest of the repeats; decoder knobs: one run).
  double eye_seconds_per_frame = 0.0;
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
// single run writes (a perceived PSNR of +inf, which JSON has no number for, as null).
void to_json(nlohmann::json& j, const SweepPoint& p);
void from_json(const nlohmann::json& j, SweepPoint& p);

struct SweepKnobResult {
  const SweepKnob* knob = nullptr;
  int default_value = 0;
  ResampleSpace resample_space = ResampleSpace::Encoded;  // the space of the sequence and base it is swept around
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
  // The linear-resample-space knobs' own base (the run's space encoded, one of them chosen): the same options with
  // --resample-space linear.
  std::optional<SweepPoint> linear_base;
  std::vector<SweepKnobResult> knobs;
  // The eye of the perceived sequences.
  double pixels_per_degree = 0.0;
  double target_velocity_deg_s = 0.0;
  double eye_velocity_deg_s = 0.0;
  int scan_line = 0;
  double wall_seconds = 0.0;
  std::uint64_t recording_hash = 0;   // of the sent codes and the reference's drive codes: parts must agree on it
  std::uint64_t linear_recording_hash = 0;  // the same of the linear base's sequence, when it was recorded (else 0)
};

// The sweep's plan: every chosen knob in pipeline order, why it is skipped (empty: it applies), the base it is
// swept around and the values it takes, ascending, base value included.
struct SweepPlanKnob {
  const SweepKnob* knob = nullptr;
  int default_value = 0;                                  // its value in the base it is swept around
  ResampleSpace resample_space = ResampleSpace::Encoded;  // the space of that base
  bool linear_base = false;  // swept around the linear base (a linear-resample-space knob, the run's space encoded)
  std::string skipped;
  std::vector<int> values;
};
std::vector<SweepPlanKnob> plan_sweep(const SweepOptions& options);
// Whether a knob of the plan sweeps around the linear base, which is then a point of its own.
bool sweep_has_linear_base(const std::vector<SweepPlanKnob>& plan);
// Whether a value of a planned knob is a point of its own: every value but the base value, and every value of an
// eye-model knob (its points watch the base's output at their eye, held to the exact eye, so none is the base).
bool sweep_is_point(const SweepPlanKnob& planned, int value);
// The points of a plan, numbered as SweepShard numbers them: the base point (0), the linear base (1) when the plan
// has one, then every value of every knob that is a point (sweep_is_point()), in plan order.
std::int64_t sweep_point_count(const std::vector<SweepPlanKnob>& plan);

// The last step of a sweep, of a whole run and of a merge of its parts alike: adds the base point (the linear base
// for the knobs swept around it) as every decoder knob's base value, gives the eye-model knobs' points the base's
// decoder figures, orders the points by value, sets the memory change against the base, and throws
// std::invalid_argument when every value asked for with --values was rejected.
void finish_sweep(SweepResult& result);

// Encodes the sequence once (a second time in linear space for the knobs swept around the linear base), decodes it
// once with the reference, then once per decoder-knob point (repeats times) with FixedStreamingDecoder;
// progress(done, total) is called after every decode of the sequence. With a shard other than the whole, only its
// points are evaluated and the result is left unfinished: each base point is there only in the shard that owns it
// (though every shard that needs a base's output decodes it), no decoder knob holds its base value and the
// eye-model knobs' points hold their perceived figures alone (finish_sweep() completes them once the parts are
// merged).
SweepResult run_sweep(const SweepOptions& options,
                      const std::function<void(std::int64_t done, std::int64_t total)>& progress = {});

}  // namespace trm::cli
