#include "sweep_report.hpp"

#include "trm/encoder_json.hpp"
#include "trm/metrics.hpp"
#include "trm/plot.hpp"


#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
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

std::string db_text(double db) { return std::isinf(db) ? std::string("exact") : fixed_text(db, 2); }

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

std::string value_text(const SweepKnob& k, const SweepPoint& p) {
  const std::string label = k.value_names.empty() ? std::to_string(p.value)
                                                  : std::to_string(p.value) + " " + k.value_label(p.value);
  if (!p.is_default) return label;
  return std::string("**").append(label).append("** (base)");
}

// What an eye-model knob's visual difference is measured against.
std::string eye_reference_text(const SweepKnob& k) {
  return k.lc_model ? k.value_label(kLcModelReference) : std::string("the exact eye");
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

// A knob's values, memory or times as an axis: logarithmic when all positive and spanning a factor of 8 or more.
plot::Axis spread_axis(const std::vector<double>& values, std::string label) {
  plot::Axis a;
  a.label = std::move(label);
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  if (*lo > 0 && *hi / *lo >= 8.0) a.scale = plot::Scale::Log;
  return a;
}

// ---- Pareto fronts ----

// A point of one knob, as a candidate of a front.
struct Candidate {
  const SweepKnobResult* knob = nullptr;
  const SweepPoint* point = nullptr;
};

// The knobs of one front: the decoder's, the eye model's held to the exact eye, and the LC model's, each against its
// own reference (a front across references would set a point that is its own reference, 0, beside another's error).
enum class KnobKind { Decoder, ExactEye, LcModel };

KnobKind kind_of(const SweepKnob& k) {
  return k.lc_model ? KnobKind::LcModel : k.eye_model ? KnobKind::ExactEye : KnobKind::Decoder;
}

// Accepted points of the knobs of one kind swept in `space` (the decoder's base once).
std::vector<Candidate> candidates(const SweepResult& r, KnobKind kind, ResampleSpace space) {
  std::vector<Candidate> out;
  bool base_taken = false;
  const bool eye_model = kind != KnobKind::Decoder;
  for (const auto& k : r.knobs) {
    if (!k.skipped.empty() || kind_of(*k.knob) != kind || k.resample_space != space) continue;
    for (const auto& p : k.points) {
      if (!p.ok()) continue;
      if (p.is_default && !eye_model) {
        if (base_taken) continue;
        base_taken = true;
      }
      out.push_back({&k, &p});
    }
  }
  return out;
}

// One front: what costs (x) and what errs (y) for each candidate.
struct Front {
  std::string name;
  std::string cost_label, cost_unit, error_label;
  std::vector<Candidate> points;
  std::vector<double> cost, error;
  std::vector<std::size_t> front;  // indices into points, ascending cost
};

Front make_front(std::string name, std::string cost_label, std::string cost_unit, std::string error_label,
                 std::vector<Candidate> points, const std::function<double(const SweepPoint&)>& cost,
                 const std::function<double(const SweepPoint&)>& error) {
  Front f{std::move(name), std::move(cost_label), std::move(cost_unit), std::move(error_label), std::move(points),
          {}, {}, {}};
  for (const Candidate& c : f.points) {
    f.cost.push_back(cost(*c.point));
    f.error.push_back(error(*c.point));
  }
  f.front = pareto_front(f.cost, f.error);
  return f;
}

double total_kib(const SweepPoint& p) { return static_cast<double>(p.on_chip_bits + p.off_chip_bits) / 8.0 / 1024.0; }

// The fronts of the run: decoder error against decode time and against memory, eye-model error against its time,
// and (when the LC model was swept) the LC model's error against the eye-model time.
std::vector<Front> fronts(const SweepResult& r) {
  const ResampleSpace space = r.options.pipeline.encoder.resample_space;
  const auto decoder = candidates(r, KnobKind::Decoder, space);
  const auto mean_lsb = [](const SweepPoint& p) { return p.mean_lsb; };
  const auto eye_ms = [](const SweepPoint& p) { return p.eye_seconds_per_frame * 1e3; };
  const auto visual_difference = [](const SweepPoint& p) { return p.visual_difference; };
  std::vector<Front> out = {
      make_front("decoder: error vs decode time", "decode time per view, ms (fastest of the repeats)", "ms/view",
                 "mean |d| vs reference (output LSB)", decoder,
                 [](const SweepPoint& p) { return p.min_seconds_per_frame * 1e3; }, mean_lsb),
      make_front("decoder: error vs memory", "on + off chip memory (KiB)", "KiB", "mean |d| vs reference (output LSB)",
                 decoder, total_kib, mean_lsb),
      make_front("eye model: error vs run time", "eye-model time per frame, ms", "ms/frame",
                 "visual difference vs the exact eye", candidates(r, KnobKind::ExactEye, space), eye_ms,
                 visual_difference)};
  std::vector<Candidate> lc = candidates(r, KnobKind::LcModel, space);
  if (!lc.empty()) {
    const std::string error_label = "visual difference vs " + eye_reference_text(*lc.front().knob->knob);
    out.push_back(make_front("LC model: error vs eye-model time", "eye-model time per frame, ms", "ms/frame",
                             error_label, std::move(lc), eye_ms, visual_difference));
  }
  return out;
}

std::string candidate_name(const Candidate& c) {
  return c.knob->knob->name + " " + c.knob->knob->value_label(c.point->value) + (c.point->is_default ? " (base)" : "");
}

std::string pareto_table_md(const SweepResult& r) {
  std::ostringstream s;
  s << "Points no other point of the same chart beats in both cost and error (cost ≤ and error ≤, one of them <); "
       "decoder points of the run's resample space, the base once.\n\n"
       "| front | point | mean LSB | max | identical | PSNR dB | visual diff. | cost |\n"
       "|---|---|---|---|---|---|---|---|\n";
  for (const Front& f : fronts(r)) {
    for (std::size_t i : f.front) {
      const SweepPoint& p = *f.points[i].point;
      s << "| " << f.name << " | `" << candidate_name(f.points[i]) << "` | " << scientific(p.mean_lsb) << " | "
        << general(p.max_lsb) << " | " << percent_text(p) << " | " << db_text(p.perceived_psnr_db) << " | "
        << scientific(p.visual_difference) << " | " << fixed_text(f.cost[i], 2) << " " << f.cost_unit << " |\n";
    }
  }
  return s.str();
}


}  // namespace

std::string sweep_csv(const SweepResult& r) {
  const std::vector<std::string> columns = {
      "knob", "resample_space", "value", "value_label", "is_default", "status", "message", "identical_percent",
      "differing_codes", "codes", "max_lsb", "mean_lsb", "rms_lsb", "linear_max", "linear_rms", "drive_max_lsb",
      "perceived_psnr_db", "visual_difference", "residual_saturated", "residual_rounded", "seconds_per_frame",
      "min_seconds_per_frame", "reference_seconds_per_frame", "setup_seconds", "eye_seconds_per_frame",
      "on_chip_bits", "off_chip_bits", "delta_on_chip_bits", "delta_off_chip_bits", "residual_format",
      "meets_criterion"};
  std::ostringstream s;
  const auto row = [&s](const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i) s << (i ? "," : "") << csv_field(fields[i]);
    s << "\n";
  };
  row(columns);
  for (const auto& k : r.knobs) {
    for (const auto& p : k.points) {
      std::vector<std::string> f = {k.knob->name, trm::to_string(k.resample_space), std::to_string(p.value),
                                    k.knob->value_label(p.value), p.is_default ? "1" : "0", p.status, p.message};
      if (p.ok()) {
        for (const std::string& v :
             {general(p.identical_percent), std::to_string(p.differing), std::to_string(p.codes), general(p.max_lsb),
              general(p.mean_lsb), general(p.rms_lsb), general(p.linear_max), general(p.linear_rms),
              general(p.drive_max_lsb), general(p.perceived_psnr_db), general(p.visual_difference),
              std::to_string(p.residual_saturated), std::to_string(p.residual_rounded), general(p.seconds_per_frame),
              general(p.min_seconds_per_frame), general(r.reference_seconds_per_frame), general(p.setup_seconds),
              general(p.eye_seconds_per_frame), std::to_string(p.on_chip_bits), std::to_string(p.off_chip_bits),
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
  s << "| knob | base | range | cheapest value meeting the criterion | identical | max | mean | PSNR dB | visual diff. "
       "| on-chip KiB | off-chip KiB | Δ memory KiB | decode ms/frame | min ms | eye ms/frame |\n"
       "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& k : r.knobs) {
    if (!k.skipped.empty()) continue;
    const SweepPoint* c = k.knob->eye_model ? nullptr : k.cheapest_meeting();
    s << "| `" << k.knob->name << "`" << (k.resample_space == ResampleSpace::Linear ? " (linear space)" : "") << " | "
      << k.default_value << " | " << k.points.front().value << "–" << k.points.back().value << " | ";
    if (k.knob->eye_model) {
      s << "— (no code criterion: the base decoder, watched) | | | | | | | | | | | |\n";
    } else if (c) {
      s << c->value << " | " << percent_text(*c) << " | " << general(c->max_lsb) << " | " << scientific(c->mean_lsb)
        << " | " << db_text(c->perceived_psnr_db) << " | " << scientific(c->visual_difference) << " | "
        << kib(c->on_chip_bits) << " | " << kib(c->off_chip_bits) << " | "
        << signed_kib(c->delta_on_chip_bits + c->delta_off_chip_bits) << " | " << ms(c->seconds_per_frame) << " | "
        << ms(c->min_seconds_per_frame) << " | " << ms(c->eye_seconds_per_frame) << " |\n";
    } else {
      s << "none | | | | | | | | | | | |\n";
    }
  }
  return s.str();
}

}  // namespace

std::string sweep_markdown(const SweepResult& r) {
  std::ostringstream s;
  const auto& o = r.options;
  s << "# Every knob: error against run time and memory\n\n";
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
  s << "* perceived sequence (`sweep_perceived.hpp`): eye 0's drive codes through the panel's light over time and the "
       "eye model (" << fixed_text(r.pixels_per_degree, 2) << " ppd, pursuing the target at "
    << fixed_text(r.target_velocity_deg_s, 1) << " deg/s with the eye at " << fixed_text(r.eye_velocity_deg_s, 1)
    << " deg/s, supplement Eq. 3): PSNR (sRGB) of the retinal image of every frame pair, and the visual difference "
       "energy (supplement Eqs. 1–4) of the x–t image of row " << r.scan_line << " in the target's frame. Decoder "
       "knobs: against the reference decoder's sequence seen by the same eye (" << kDefaultRetinaSubsteps
    << " sub-steps); eye-model knobs: the base decoder watched with the knob's value, against the reference "
       "decoder's sequence seen by the exact eye (" << kExactEyeSubsteps << " sub-steps); the LCD's LC model "
       "(`lc_model`): the base decoder's sequence through each LC model, against the same sequence through the "
       "reference LC (" << lc_model_names()[kLcModelReference] << "), both at the base eye (" << kDefaultRetinaSubsteps
    << " sub-steps), so a point differs from its reference in the LC alone; eye ms/frame: that eye model's time "
       "per frame watched\n";
  if (r.linear_base) {
    s << "* linear-resample-space knobs: swept around a base of their own, the same options with "
         "`--resample-space linear` (its own sequence and reference): base "
      << percent_text(*r.linear_base) << " identical, max " << general(r.linear_base->max_lsb) << " LSB, "
      << kib(r.linear_base->on_chip_bits) << " KiB on chip, " << kib(r.linear_base->off_chip_bits)
      << " KiB off chip\n";
  }
  s << "\n## Pareto front\n\n![Pareto front](sweep_pareto.png)\n\n" << pareto_table_md(r) << "\n";
  s << "## Summary\n\n" << summary_table_md(r) << "\n";
  for (const auto& k : r.knobs) {
    s << "## `" << k.knob->name << "`\n\n" << k.knob->description << ". Cost: " << k.knob->cost << ".\n\n";
    if (!k.skipped.empty()) {
      s << "Skipped: " << k.skipped << ".\n\n";
      continue;
    }
    if (k.resample_space == ResampleSpace::Linear && r.linear_base) {
      s << "Swept around the linear-resample-space base (memory Δ against it).\n\n";
    }
    s << "![" << k.knob->name << "](sweep_" << k.knob->name << ".png)\n\n";
    s << "| value | identical | max | mean | RMS | linear max | linear RMS | drive v max | PSNR dB | visual diff. "
         "| ms/frame | min ms | eye ms/frame | on-chip KiB | off-chip KiB | Δ memory KiB | meets |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& p : k.points) {
      s << "| " << value_text(*k.knob, p) << " | ";
      if (!p.ok()) {
        s << p.status << ": " << md_cell(p.message) << " | | | | | | | | | | | | | | | |\n";
        continue;
      }
      s << percent_text(p) << " | " << general(p.max_lsb) << " | " << scientific(p.mean_lsb) << " | "
        << scientific(p.rms_lsb) << " | " << scientific(p.linear_max) << " | " << scientific(p.linear_rms) << " | "
        << fixed_text(p.drive_max_lsb, 3) << " | " << db_text(p.perceived_psnr_db) << " | "
        << scientific(p.visual_difference) << " | " << ms(p.seconds_per_frame) << " | " << ms(p.min_seconds_per_frame)
        << " | " << ms(p.eye_seconds_per_frame) << " | " << kib(p.on_chip_bits) << " | "
        << kib(p.off_chip_bits) << " | " << signed_kib(p.delta_on_chip_bits + p.delta_off_chip_bits) << " | "
        << (p.meets_criterion() ? "yes" : "no") << " |\n";
    }
    s << "\n";
  }
  return s.str();
}

Json sweep_parameters_json(const SweepResult& r) {
  const auto& o = r.options;
  const auto& po = o.pipeline;
  return {{"source", source_text(o)},
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
}

Json sweep_json(const SweepResult& r) {
  Json j;
  j["tool"] = "trm sweep";
  j["command"] = r.options.command;
  j["parameters"] = sweep_parameters_json(r);
  j["criterion"] = {{"identical_percent_at_least", kReferenceAgreementCriterion.min_identical_percent()},
                    {"max_lsb_at_most", kReferenceAgreementCriterion.max_lsb}};
  j["reference_seconds_per_frame"] = r.reference_seconds_per_frame;
  // A knob's point (`knob` set: an index knob's points carry their value's name) or a base point.
  const auto point_json = [&](const SweepPoint& p, const SweepKnob* knob) {
    Json pj;
    pj["value"] = p.value;
    if (knob && !knob->value_names.empty()) pj["value_label"] = knob->value_label(p.value);
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
    // +inf (identical) has no JSON number: null.
    pj["perceived"] = {{"psnr_db", std::isinf(p.perceived_psnr_db) ? Json(nullptr) : Json(p.perceived_psnr_db)},
                       {"visual_difference", p.visual_difference}};
    pj["residual_events"] = {{"saturated", p.residual_saturated}, {"rounded", p.residual_rounded}};
    pj["time"] = {{"seconds_per_frame", p.seconds_per_frame},
                  {"min_seconds_per_frame", p.min_seconds_per_frame},
                  {"repeat_seconds_per_frame", p.repeat_seconds_per_frame},
                  {"setup_seconds", p.setup_seconds},
                  {"eye_seconds_per_frame", p.eye_seconds_per_frame}};
    pj["memory"] = {{"on_chip_bits", p.on_chip_bits},
                    {"off_chip_bits", p.off_chip_bits},
                    {"delta_on_chip_bits", p.delta_on_chip_bits},
                    {"delta_off_chip_bits", p.delta_off_chip_bits}};
    pj["residual_format"] = p.residual_format;
    pj["meets_criterion"] = p.meets_criterion();
    return pj;
  };
  j["eye"] = {{"pixels_per_degree", r.pixels_per_degree},
              {"target_velocity_deg_s", r.target_velocity_deg_s},
              {"eye_velocity_deg_s", r.eye_velocity_deg_s},
              {"scan_line", r.scan_line},
              {"substeps", kDefaultRetinaSubsteps},
              {"exact_substeps", kExactEyeSubsteps},
              {"lc_model_reference", lc_model_names()[kLcModelReference]}};
  j["base"] = point_json(r.base, nullptr);
  if (r.linear_base) j["linear_base"] = point_json(*r.linear_base, nullptr);
  Json pareto = Json::array();
  for (const Front& f : fronts(r)) {
    Json points = Json::array();
    for (std::size_t i : f.front) {
      const SweepKnob& knob = *f.points[i].knob->knob;
      points.push_back({{"knob", knob.name}, {"value", f.points[i].point->value},
                        {"value_label", knob.value_label(f.points[i].point->value)},
                        {"is_default", f.points[i].point->is_default}, {"cost", f.cost[i]}, {"error", f.error[i]}});
    }
    pareto.push_back({{"chart", f.name}, {"cost", f.cost_label}, {"error", f.error_label}, {"front", points}});
  }
  j["pareto"] = std::move(pareto);
  Json knobs = Json::array();
  for (const auto& k : r.knobs) {
    Json kj;
    kj["name"] = k.knob->name;
    kj["description"] = k.knob->description;
    kj["cost"] = k.knob->cost;
    kj["base_value"] = k.default_value;
    kj["resample_space"] = trm::to_string(k.resample_space);
    kj["eye_model"] = k.knob->eye_model;
    if (!k.skipped.empty()) {
      kj["skipped"] = k.skipped;
    } else {
      const SweepPoint* c = k.cheapest_meeting();
      kj["cheapest_meeting_criterion"] = c ? Json(c->value) : Json(nullptr);
      Json points = Json::array();
      for (const auto& p : k.points) points.push_back(point_json(p, k.knob));
      kj["points"] = std::move(points);
    }
    knobs.push_back(std::move(kj));
  }
  j["knobs"] = std::move(knobs);
  j["wall_seconds"] = r.wall_seconds;
  return j;
}

void write_sweep_plot(const std::filesystem::path& path, const SweepResult& r, const SweepKnobResult& k) {
  std::vector<const SweepPoint*> points;
  for (const auto& p : k.points) {
    if (p.ok()) points.push_back(&p);
  }
  plot::Figure figure;
  figure.width = 1620;
  figure.height = 500;
  figure.title = k.knob->name;
  figure.title.append(": ").append(k.knob->description);
  figure.subtitle = header_line(r);
  figure.subtitle.append("; memory at ").append(std::to_string(r.options.hw_size.width)).append("x").append(
      std::to_string(r.options.hw_size.height));
  const int rejected = static_cast<int>(k.points.size() - points.size());
  if (rejected > 0) {
    figure.subtitle.append("; ").append(std::to_string(rejected)).append(" value(s) rejected, not drawn");
  }
  if (points.empty()) {
    plot::Chart chart;
    chart.note = "no value of this knob was accepted";
    figure.charts = {chart};
    plot::write_png(path, figure);
    return;
  }

  bool on_varies = false, off_varies = false;
  for (const SweepPoint* p : points) {
    on_varies = on_varies || p->on_chip_bits != points.front()->on_chip_bits;
    off_varies = off_varies || p->off_chip_bits != points.front()->off_chip_bits;
  }
  const bool eye = k.knob->eye_model;
  std::vector<double> x_value, x_memory, x_time, max_lsb, rms_lsb, mean_lsb, visual_difference;
  std::vector<std::string> labels;
  const SweepPoint* base = nullptr;
  for (const SweepPoint* p : points) {
    if (p->is_default) base = p;
    x_value.push_back(p->value);
    const std::int64_t bits = off_varies && on_varies ? p->on_chip_bits + p->off_chip_bits
                              : off_varies            ? p->off_chip_bits
                                                      : p->on_chip_bits;
    x_memory.push_back(static_cast<double>(bits) / 8.0 / 1024.0);
    x_time.push_back((eye ? p->eye_seconds_per_frame : p->min_seconds_per_frame) * 1e3);
    visual_difference.push_back(p->visual_difference);
    max_lsb.push_back(p->max_lsb);
    rms_lsb.push_back(p->rms_lsb);
    mean_lsb.push_back(p->mean_lsb);
    labels.push_back(k.knob->value_label(p->value));
  }
  const std::string memory_label = on_varies && off_varies ? "on + off chip memory (KiB)"
                                   : off_varies            ? "off-chip memory (KiB)"
                                                           : "on-chip memory (KiB)";
  // The errors against one x (the code errors; an eye-model knob, which leaves the codes alone: the visual
  // difference); zeros (exact agreement) sit hollow on the lower edge of the log error axis.
  struct Error {
    const char* label;
    const std::vector<double>* y;
    int colour;
  };
  const std::vector<Error> errors =
      eye ? std::vector<Error>{{"visual difference", &visual_difference, 1}}
          : std::vector<Error>{{"max |d|", &max_lsb, 3}, {"RMS |d|", &rms_lsb, 2}, {"mean |d|", &mean_lsb, 0}};
  const auto chart = [&](std::string title, const std::vector<double>& x, plot::Axis x_axis, plot::Style style,
                         bool value_labels) {
    plot::Chart c;
    c.title = std::move(title);
    c.x = std::move(x_axis);
    c.y.label = eye ? "visual difference vs " + eye_reference_text(*k.knob) + ", 0 on the lower edge"
                    : "error vs reference (output LSB), 0 on the lower edge";
    c.y.scale = plot::Scale::Log;
    c.y.nonpositive_on_edge = true;
    for (const Error& e : errors) {
      c.series.push_back({.label = e.label, .x = x, .y = *e.y, .style = style, .colour = e.colour});
    }
    if (value_labels) c.series.front().point_labels = labels;
    if (base) {
      const auto i = static_cast<std::size_t>(std::find(points.begin(), points.end(), base) - points.begin());
      for (const Error& e : errors) c.rings.push_back({x[i], (*e.y)[i]});
      c.rings_label = "base value";
    }
    return c;
  };
  figure.charts = {
      chart("error vs knob value", x_value, spread_axis(x_value, k.knob->name), plot::Style::LineAndPoints, false),
      chart(on_varies || off_varies ? "error vs memory" : "error vs memory (unchanged by this knob)", x_memory,
            spread_axis(x_memory, memory_label), plot::Style::LineAndPoints, true),
      eye ? chart("error vs eye-model time", x_time, spread_axis(x_time, "eye-model time per frame, ms (fastest of "
                                                                       "the repeats)"),
                  plot::Style::Points, true)
          : chart("error vs decode time", x_time,
                  spread_axis(x_time, "decode time per view, ms (fastest of the repeats)"), plot::Style::Points, true)};
  plot::write_png(path, figure);
}

std::vector<std::size_t> pareto_front(const std::vector<double>& cost, const std::vector<double>& error) {
  if (cost.size() != error.size()) throw std::invalid_argument("pareto_front: cost and error differ in length");
  std::vector<std::size_t> order(cost.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  // By cost, then error: a point is on the front when its error is below every cheaper (or equally cheap, less
  // erring) point's. Equal points are all on it.
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return cost[a] != cost[b] ? cost[a] < cost[b] : error[a] < error[b];
  });
  std::vector<std::size_t> front;
  for (std::size_t i : order) {
    if (front.empty()) {
      front.push_back(i);
      continue;
    }
    const std::size_t last = front.back();
    const bool same = cost[i] == cost[last] && error[i] == error[last];
    if (same || error[i] < error[last]) front.push_back(i);
  }
  return front;
}

void write_pareto_plot(const std::filesystem::path& path, const SweepResult& r) {
  plot::Figure figure;
  const std::vector<Front> all = fronts(r);
  figure.width = 600 * static_cast<int>(all.size());
  figure.height = 560;
  figure.title = "Pareto fronts: error against run time and memory, every knob swept alone";
  figure.subtitle = header_line(r);
  figure.subtitle.append("; memory at ").append(std::to_string(r.options.hw_size.width)).append("x").append(
      std::to_string(r.options.hw_size.height));
  for (const Front& f : all) {
    plot::Chart chart;
    chart.title = f.name;
    chart.y.label = f.error_label + ", 0 on the lower edge";
    chart.y.scale = plot::Scale::Log;
    chart.y.nonpositive_on_edge = true;
    if (f.points.empty()) {
      chart.note = "no knob of this kind was swept";
      figure.charts.push_back(std::move(chart));
      continue;
    }
    chart.x = spread_axis(f.cost, f.cost_label);
    // Room on the right for the front's labels.
    const auto [lo, hi] = std::minmax_element(f.cost.begin(), f.cost.end());
    const double span = *hi - *lo > 0 ? *hi - *lo : std::max(std::abs(*hi), 1.0);
    chart.x.max = chart.x.scale == plot::Scale::Log ? *hi * 3.0 : *hi + 0.25 * span;
    std::vector<double> front_x, front_y;
    std::vector<std::string> labels;
    for (std::size_t i : f.front) {
      front_x.push_back(f.cost[i]);
      front_y.push_back(f.error[i]);
      labels.push_back(candidate_name(f.points[i]));
    }
    chart.series = {{.label = "every point", .x = f.cost, .y = f.error, .style = plot::Style::Points, .colour = 7},
                    {.label = "Pareto front", .x = front_x, .y = front_y, .style = plot::Style::LineAndPoints,
                     .colour = 1, .point_labels = labels}};
    for (std::size_t i = 0; i < f.points.size(); ++i) {
      if (f.points[i].point->is_default) {
        chart.rings.push_back({f.cost[i], f.error[i]});
        break;
      }
    }
    chart.rings_label = "default";
    figure.charts.push_back(std::move(chart));
  }
  plot::write_png(path, figure);
}

std::string sweep_summary(const SweepResult& r) {
  std::ostringstream s;
  s << "  " << header_line(r) << "\n  reference " << ms(r.reference_seconds_per_frame) << " ms/view; base "
    << percent_text(r.base) << " identical, max " << general(r.base.max_lsb) << " LSB, "
    << ms(r.base.seconds_per_frame) << " ms/view, " << kib(r.base.on_chip_bits) << " KiB on / "
    << kib(r.base.off_chip_bits) << " KiB off chip at " << r.options.hw_size.width << "x" << r.options.hw_size.height
    << "; perceived PSNR " << db_text(r.base.perceived_psnr_db)
    << (std::isinf(r.base.perceived_psnr_db) ? "" : " dB") << ", visual difference "
    << scientific(r.base.visual_difference)
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
    if (k.knob->eye_model) {
      s << "   eye model (base decoder): visual difference vs " << eye_reference_text(*k.knob);
      for (const SweepPoint& p : k.points) {
        if (p.ok()) s << " " << k.knob->value_label(p.value) << ":" << scientific(p.visual_difference);
      }
      s << "\n";
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
