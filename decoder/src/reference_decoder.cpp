// The reference TRM decoder in double precision, stage by stage as in DESIGN §4 (paper Eqs. 1-7).
//
// Full frame t (codes E_t):
//   d_t = Q_b(D(E_t)), L_t = lin(U(d_t)), I_t = lin(E_t), beta = 2 I_t - L_t (Eq. 2),
//   shown = clamp(beta, 0, 1), rho_t = beta - shown (Sec. 4.2).
// Reduced frame t + 1 (codes i):
//   alpha = lin(U(i)) (Eq. 1), c = |Y(L_t) - Y(alpha)| / (Y(L_t) + Y(alpha)) (Eq. 5),
//   w = exp(-s c) (Eq. 6), alpha' = clamp(alpha + w rho_t, 0, 1) (Eq. 4).
// Then the panel inverse (Sec. 4.4): OLED v = x^(1/gamma_c); LCD solves Eq. 7 for v_t given v_{t-1}.
#include "trm/reference_decoder.hpp"

#include "view_arrival.hpp"

#include "trm/resample.hpp"
#include "trm/transfer.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace trm {

namespace {

// Rec. 709 luma weights on linear RGB (DESIGN §3).
constexpr double kLumaR = 0.2126;
constexpr double kLumaG = 0.7152;
constexpr double kLumaB = 0.0722;

int max_code(int bits) { return (1 << bits) - 1; }

// ---------------------------------------------------------------------------------------------------------
// Stages shared by both parities.

// I = lin(E): received codes to linear light. A code has only 2^b values, so lin(code / (2^b - 1)) is tabulated:
// the same doubles as to_linear(dequantise(E)), at a fraction of the cost of a pow per sample.
cv::Mat linear_from_codes(const cv::Mat& codes, const EncoderConfig& link) {
  const int top = max_code(link.bits);
  std::vector<double> table(static_cast<std::size_t>(top) + 1);
  for (int code = 0; code <= top; ++code) {
    table[static_cast<std::size_t>(code)] = to_linear(static_cast<double>(code) / top, link.transfer);
  }
  cv::Mat linear(codes.size(), CV_64FC3);
  const cv::Mat in = codes.reshape(1);
  cv::Mat out = linear.reshape(1);
  for (int y = 0; y < in.rows; ++y) {
    const std::uint16_t* c_row = in.ptr<std::uint16_t>(y);
    double* l_row = out.ptr<double>(y);
    for (int k = 0; k < in.cols; ++k) l_row[k] = table[c_row[k]];
  }
  return linear;
}

// The upsampled low-pass frame in linear light: L_t = lin(U(d_t)) (Eq. 2) or alpha = lin(U(i_t)) (Eq. 1).
// D and U act on encoded values by default (Sec. 4.2); in the linear resample space U acts on lin(d).
cv::Mat upsampled_linear(const cv::Mat& reduced_codes, cv::Size full, const EncoderConfig& link) {
  const cv::Mat encoded = dequantise(reduced_codes, link.bits);
  if (link.resample_space == ResampleSpace::Encoded) {
    return to_linear(upsample(encoded, full.width, full.height), link.transfer);
  }
  return upsample(to_linear(encoded, link.transfer), full.width, full.height);
}

// Sum / count (cv::mean multiplies by 1 / count, which can turn an all-ones mean into 1 - 1ulp).
double mean_of(const cv::Mat& single_channel) {
  double sum = 0.0;
  for (int y = 0; y < single_channel.rows; ++y) {
    const double* row = single_channel.ptr<double>(y);
    for (int x = 0; x < single_channel.cols; ++x) sum += row[x];
  }
  return sum / static_cast<double>(single_channel.total());
}

struct ResidualSummary {
  double mean_abs = 0.0;
  double max_abs = 0.0;
};

ResidualSummary summarise_residual(const cv::Mat& residual) {
  ResidualSummary summary;
  if (residual.empty()) return summary;
  double sum = 0.0;
  const cv::Mat flat = residual.reshape(1);
  for (int y = 0; y < flat.rows; ++y) {
    const double* row = flat.ptr<double>(y);
    for (int k = 0; k < flat.cols; ++k) {
      const double magnitude = std::abs(row[k]);
      sum += magnitude;
      summary.max_abs = std::max(summary.max_abs, magnitude);
    }
  }
  summary.mean_abs = sum / static_cast<double>(flat.total());
  return summary;
}

// ---------------------------------------------------------------------------------------------------------
// Full-frame stages (Eq. 2, Sec. 4.2).

// Eq. 2: beta = 2 I - L, the compensated frame; it may leave [0, 1].
cv::Mat compensate(const cv::Mat& full_linear, const cv::Mat& low_linear) {
  cv::Mat beta(full_linear.size(), CV_64FC3);
  const cv::Mat in = full_linear.reshape(1);
  const cv::Mat low = low_linear.reshape(1);
  cv::Mat out = beta.reshape(1);
  for (int y = 0; y < in.rows; ++y) {
    const double* i_row = in.ptr<double>(y);
    const double* l_row = low.ptr<double>(y);
    double* b_row = out.ptr<double>(y);
    for (int k = 0; k < in.cols; ++k) b_row[k] = 2.0 * i_row[k] - l_row[k];
  }
  return beta;
}

// Sec. 4.2: the displayable part shown = clamp(beta, 0, 1) and the residual rho = beta - shown that the next
// reduced frame makes up for. Returns the number of channel samples outside [0, 1].
std::size_t split_displayable(const cv::Mat& beta, cv::Mat& shown, cv::Mat& residual) {
  shown.create(beta.size(), CV_64FC3);
  residual.create(beta.size(), CV_64FC3);
  const cv::Mat in = beta.reshape(1);
  cv::Mat shown_flat = shown.reshape(1);
  cv::Mat residual_flat = residual.reshape(1);
  std::size_t clipped = 0;
  for (int y = 0; y < in.rows; ++y) {
    const double* b_row = in.ptr<double>(y);
    double* s_row = shown_flat.ptr<double>(y);
    double* r_row = residual_flat.ptr<double>(y);
    for (int k = 0; k < in.cols; ++k) {
      const double value = std::clamp(b_row[k], 0.0, 1.0);
      s_row[k] = value;
      r_row[k] = b_row[k] - value;
      clipped += value != b_row[k] ? 1 : 0;
    }
  }
  return clipped;
}

// ---------------------------------------------------------------------------------------------------------
// Reduced-frame stages (Eqs. 4-6).

// Eq. 5 on Rec. 709 luma: c = |Y(L_prev) - Y(alpha)| / (Y(L_prev) + Y(alpha)), 0 where the sum is 0 (both
// black: nothing moved that could be seen). A Michelson contrast, so c is in [0, 1].
cv::Mat motion_contrast(const cv::Mat& previous_low_linear, const cv::Mat& alpha) {
  cv::Mat contrast(alpha.size(), CV_64FC1);
  for (int y = 0; y < alpha.rows; ++y) {
    const cv::Vec3d* p_row = previous_low_linear.ptr<cv::Vec3d>(y);
    const cv::Vec3d* a_row = alpha.ptr<cv::Vec3d>(y);
    double* c_row = contrast.ptr<double>(y);
    for (int x = 0; x < alpha.cols; ++x) {
      const cv::Vec3d& p = p_row[x];
      const cv::Vec3d& a = a_row[x];
      const double y_prev = kLumaR * p[0] + kLumaG * p[1] + kLumaB * p[2];
      const double y_alpha = kLumaR * a[0] + kLumaG * a[1] + kLumaB * a[2];
      const double sum = y_prev + y_alpha;
      c_row[x] = sum > 0.0 ? std::abs(y_prev - y_alpha) / sum : 0.0;
    }
  }
  return contrast;
}

// Eq. 6: w = exp(-s c). Exactly 1 where c = 0, so static content gets the whole residual even for s = +inf
// (where s c would be inf * 0 = NaN).
cv::Mat motion_weight(const cv::Mat& contrast, double sensitivity) {
  cv::Mat weight(contrast.size(), CV_64FC1);
  cv::parallel_for_(cv::Range(0, contrast.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const double* c_row = contrast.ptr<double>(y);
      double* w_row = weight.ptr<double>(y);
      for (int x = 0; x < contrast.cols; ++x) {
        w_row[x] = c_row[x] == 0.0 ? 1.0 : std::exp(-sensitivity * c_row[x]);
      }
    }
  });
  return weight;
}

struct ResidualAddition {
  cv::Mat alpha_unclamped;  // alpha + w rho
  cv::Mat alpha_prime;      // clamp(alpha + w rho, 0, 1)
  std::size_t clipped = 0;  // channel samples outside [0, 1]
  double dropped_sum = 0.0; // sum of |alpha + w rho - alpha'|
};

// Eq. 4: alpha' = clamp(alpha + w rho, 0, 1), one w per pixel shared by the channels. What the clamp drops is
// lost for good: the residual serves exactly one reduced frame.
ResidualAddition add_weighted_residual(const cv::Mat& alpha, const cv::Mat& weight, const cv::Mat& residual) {
  ResidualAddition result;
  result.alpha_unclamped.create(alpha.size(), CV_64FC3);
  result.alpha_prime.create(alpha.size(), CV_64FC3);
  for (int y = 0; y < alpha.rows; ++y) {
    const cv::Vec3d* a_row = alpha.ptr<cv::Vec3d>(y);
    const double* w_row = weight.ptr<double>(y);
    const cv::Vec3d* r_row = residual.ptr<cv::Vec3d>(y);
    cv::Vec3d* u_row = result.alpha_unclamped.ptr<cv::Vec3d>(y);
    cv::Vec3d* o_row = result.alpha_prime.ptr<cv::Vec3d>(y);
    for (int x = 0; x < alpha.cols; ++x) {
      for (int ch = 0; ch < 3; ++ch) {
        const double sum = a_row[x][ch] + w_row[x] * r_row[x][ch];
        const double kept = std::clamp(sum, 0.0, 1.0);
        u_row[x][ch] = sum;
        o_row[x][ch] = kept;
        if (kept != sum) {
          ++result.clipped;
          result.dropped_sum += std::abs(sum - kept);
        }
      }
    }
  }
  return result;
}

// ---------------------------------------------------------------------------------------------------------
// Panel drive (Sec. 4.4).

struct PanelDrive {
  cv::Mat drive;           // v before output quantisation
  cv::Mat codes;           // floor(v (2^out - 1) + 0.5)
  cv::Mat emitted_linear;  // from the quantised drive
  cv::Mat shortfall;       // LCD: x_t - x_t_eff where unreachable, else 0 (empty for OLED)
  cv::Mat contributed;     // LCD: x_t where reachable, x_t_eff where not: the x_{t-1} of the next frame
  cv::Mat target;          // LCD: m
  cv::Mat previous_drive;  // LCD: v_{t-1}
  cv::Mat unreachable;     // LCD: 255 where unreachable
  std::size_t unreachable_count = 0;
};

// The panel inverse of every sample through the panel model (DESIGN §4). With history (LCD, Eq. 7): the pair
// (v_{t-1}, v_t) is seen as the merged value M(v_t, v_{t-1}); to add x_t after a frame that contributed x_{t-1} the
// pair must merge to m, and v_{t-1} is the drive actually shown (quantised).
//
// Unreachable m: the linear shortfall x_t - x_t_eff is returned so that, for a full frame, it joins rho and the next
// reduced frame makes it up (paper Sec. 4.4: "add the difference between the desired value and the displayed value
// to the residual buffer"). It uses the unquantised v_t: drive quantisation error is never fed back (DESIGN §3).
//
// With LcdHistory::Contributed, x_t_eff rather than x_t is what the next frame's target builds on: the next pair is
// wanted to average (x_{t+1} + x_t_eff) / 2, and with x_{t+1} = alpha + rho + shortfall that is (alpha + beta) / 2 = I
// for static content. Building on the wanted x_t instead would count the shortfall twice (it is already in rho),
// leaving the pair shortfall / 2 too bright. Where m was reachable x_t_eff = x_t, so x_t is kept bit for bit. The
// design's rule (LcdHistory::Wanted, the default) builds on the wanted x_t, as independent implementations of it do.
// previous_wanted and previous_drive are read only for a panel with history.
PanelDrive drive_panel(const cv::Mat& wanted, const cv::Mat& previous_wanted, const cv::Mat& previous_drive,
                       const Panel& panel, const PanelEmission& emission, int output_bits) {
  PanelDrive out;
  const cv::Size size = wanted.size();
  const bool history = panel.has_history();
  out.drive.create(size, CV_64FC3);
  if (history) {
    out.shortfall = cv::Mat::zeros(size, CV_64FC3);
    out.contributed = wanted.clone();
    out.target.create(size, CV_64FC3);
    out.unreachable = cv::Mat::zeros(size, CV_8UC3);
    out.previous_drive = previous_drive;
  }
  // Rows on OpenCV's threads: every sample's drive is computed alone (the same doubles for any split); the
  // unreachable samples are counted per row and added up in row order.
  std::vector<std::size_t> unreachable_per_row(static_cast<std::size_t>(size.height), 0);
  cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const cv::Vec3d* x_row = wanted.ptr<cv::Vec3d>(y);
      const cv::Vec3d* xp_row = history ? previous_wanted.ptr<cv::Vec3d>(y) : nullptr;
      const cv::Vec3d* vp_row = history ? previous_drive.ptr<cv::Vec3d>(y) : nullptr;
      cv::Vec3d* v_row = out.drive.ptr<cv::Vec3d>(y);
      for (int x = 0; x < size.width; ++x) {
        for (int ch = 0; ch < 3; ++ch) {
          const double x_t = x_row[x][ch];
          const double x_prev = history ? xp_row[x][ch] : 0.0;
          const PanelDriveSample sample = panel.drive(x_t, x_prev, history ? vp_row[x][ch] : 0.0, ch);
          v_row[x][ch] = sample.v;
          if (!history) continue;
          out.target.ptr<cv::Vec3d>(y)[x][ch] = sample.target;
          if (!sample.reachable) {
            ++unreachable_per_row[static_cast<std::size_t>(y)];
            out.unreachable.ptr<cv::Vec3b>(y)[x][ch] = 255;
            out.shortfall.ptr<cv::Vec3d>(y)[x][ch] = x_t - sample.contributed;
            out.contributed.ptr<cv::Vec3d>(y)[x][ch] = sample.contributed;
          }
        }
      }
    }
  });
  for (const std::size_t count : unreachable_per_row) out.unreachable_count += count;
  out.codes = quantise(out.drive, output_bits);

  const int top = max_code(output_bits);
  out.emitted_linear.create(size, CV_64FC3);
  cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const cv::Vec3w* q_row = out.codes.ptr<cv::Vec3w>(y);
      const cv::Vec3d* vp_row = history ? previous_drive.ptr<cv::Vec3d>(y) : nullptr;
      cv::Vec3d* e_row = out.emitted_linear.ptr<cv::Vec3d>(y);
      for (int x = 0; x < size.width; ++x) {
        for (int ch = 0; ch < 3; ++ch) {
          const auto previous_code = history ? static_cast<std::uint16_t>(std::lround(vp_row[x][ch] * top)) : 0;
          e_row[x][ch] = emission(q_row[x][ch], previous_code, ch);
        }
      }
    }
  });
  return out;
}

// The first LCD frame of an eye has no history: treat the panel as having held this same frame, i.e.
// x_{t-1} = x_t and v_{t-1} = the held drive of x_t (M(v, v) = x_t^(1/gamma)), quantised as any shown drive.
std::pair<cv::Mat, cv::Mat> held_history(const cv::Mat& wanted, const Panel& panel, int output_bits) {
  cv::Mat held_drive(wanted.size(), CV_64FC3);
  cv::parallel_for_(cv::Range(0, wanted.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const cv::Vec3d* x_row = wanted.ptr<cv::Vec3d>(y);
      cv::Vec3d* v_row = held_drive.ptr<cv::Vec3d>(y);
      for (int x = 0; x < wanted.cols; ++x) {
        for (int ch = 0; ch < 3; ++ch) v_row[x][ch] = panel.drive_from_linear(x_row[x][ch], ch);
      }
    }
  });
  return {wanted.clone(), dequantise(quantise(held_drive, output_bits), output_bits)};
}

// Adds the LCD shortfall to rho (full frames only).
void add_shortfall(cv::Mat& residual, const cv::Mat& shortfall) { residual += shortfall; }

}  // namespace

void DecoderConfig::validate() const {
  link.validate();
  // s = 10 (the default): c is a Michelson contrast in [0, 1]; exp(-10 c) keeps w >= 0.8 for the ~2 % contrast
  // changes that link quantisation alone produces, and fades the residual below 0.14 at 20 % contrast, where
  // adding it would ghost. The paper leaves s as a tuning parameter (Eq. 6).
  if (std::isnan(sensitivity) || sensitivity < 0.0 || (std::isfinite(sensitivity) && sensitivity > kMaxFiniteSensitivity)) {
    std::ostringstream message;
    message << "DecoderConfig: motion sensitivity s (--sensitivity) must be in [0, " << kMaxFiniteSensitivity
            << "] or infinite (the motion weight's s register is uQ8), got " << sensitivity;
    throw std::invalid_argument(message.str());
  }
  if (output_bits != 8 && output_bits != 10) {
    throw std::invalid_argument("DecoderConfig: output_bits must be 8 or 10 (got " + std::to_string(output_bits) +
                                ")");
  }
  panel.validate("DecoderConfig: ");
}

ReferenceDecoder::ReferenceDecoder(DecoderConfig config)
    : config_((config.validate(), std::move(config))), emission_(config_.panel, config_.output_bits) {}

DecodedFrame ReferenceDecoder::decode_lost(const FrameMeta& meta) {
  detail::check_lost_view(meta, "ReferenceDecoder");
  return detail::hold_lost_view(eyes_[meta.eye], meta);
}

DecodedFrame ReferenceDecoder::decode(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) {
  detail::Concealment lost;
  switch (detail::classify_arrival(frame, line_intact, lost, "ReferenceDecoder")) {
    case detail::Arrival::Whole: return decode(frame);
    case detail::Arrival::Lost: return decode_lost(frame.meta);
    case detail::Arrival::Partial: break;
  }
  lost.substitute = detail::concealment_substitute(eyes_, frame);
  const LinkFrame concealed{frame.meta, detail::concealed_codes(frame.codes, lost)};
  DecodedFrame out = decode_view(concealed, line_intact);
  out.stats.concealed_lines = lost.lost_lines;
  return out;
}

DecodedFrame ReferenceDecoder::decode(const LinkFrame& frame) { return decode_view(frame, {}); }

void ReferenceDecoder::adopt_panel_history(const DecodedFrame& shown) {
  if (!config_.panel.has_history()) {
    throw std::invalid_argument("ReferenceDecoder: adopt_panel_history is for LCD panels (an OLED has no history)");
  }
  const auto found = eyes_.find(shown.meta.eye);
  if (found == eyes_.end() || found->second.previous_drive.empty()) {
    throw std::invalid_argument("ReferenceDecoder: eye " + std::to_string(shown.meta.eye) +
                                " has no LCD history to replace (decode a frame of it first)");
  }
  EyeState& eye = found->second;
  if (shown.drive_codes.size() != eye.previous_drive.size() || shown.drive_codes.type() != CV_16UC3) {
    throw std::invalid_argument("ReferenceDecoder: adopt_panel_history needs the eye's view size in CV_16UC3 codes");
  }
  double max_code = 0.0;
  cv::minMaxLoc(shown.drive_codes.reshape(1), nullptr, &max_code);
  if (max_code > (1 << config_.output_bits) - 1) {
    throw std::invalid_argument("ReferenceDecoder: adopted drive codes exceed " + std::to_string(config_.output_bits) +
                                " bits");
  }
  eye.previous_drive = dequantise(shown.drive_codes, config_.output_bits);
}

DecodedFrame ReferenceDecoder::decode_view(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) {
  detail::check_link_frame(frame, config_.link, "ReferenceDecoder");
  const FrameMeta& meta = frame.meta;
  const EncoderConfig& link = config_.link;
  const cv::Size full(meta.full_width, meta.full_height);
  const double samples = 3.0 * static_cast<double>(full.width) * full.height;

  EyeState& eye = eyes_[meta.eye];
  if (eye.full_size != full) {
    // A new view size starts a new stream for this eye: no residual, no panel history.
    eye = EyeState();
    eye.full_size = full;
  }

  DecodedFrame out;
  out.meta = meta;
  out.meta.width = full.width;
  out.meta.height = full.height;
  DecodeStages stages;

  cv::Mat wanted;  // x_t: what this frame should add to the pair, in linear light, within [0, 1]
  if (meta.parity == Parity::Full) {
    const cv::Mat low_codes = reduce_codes(frame.codes, link);         // d_t, as the encoder sends it
    const cv::Mat low_linear = upsampled_linear(low_codes, full, link);  // L_t
    const cv::Mat full_linear = linear_from_codes(frame.codes, link);    // I_t
    cv::Mat beta = compensate(full_linear, low_linear);                  // Eq. 2
    // Concealment: a lost line has no trustworthy beta; it shows L_t (within [0, 1], so its rho is 0).
    for (int y = 0; y < static_cast<int>(line_intact.size()); ++y) {
      if (!line_intact[static_cast<std::size_t>(y)]) low_linear.row(y).copyTo(beta.row(y));
    }
    cv::Mat residual;
    const std::size_t clipped = split_displayable(beta, wanted, residual);

    out.stats.clipped_fraction = static_cast<double>(clipped) / samples;
    eye.have_residual = true;
    eye.residual_index = meta.index;
    eye.residual = residual;
    eye.previous_low = low_codes;
    if (config_.record_stages) {
      stages.at(Stage::Codes) = frame.codes;
      stages.at(Stage::Reduced) = low_codes;
      stages.at(Stage::LowPass) = low_linear;
      stages.at(Stage::Linear) = full_linear;
      stages.at(Stage::Beta) = beta;
      stages.at(Stage::Shown) = wanted;
    }
  } else {
    const cv::Mat alpha = upsampled_linear(frame.codes, full, link);  // Eq. 1
    // meta.index >= 0 (check_link_frame), so index - 1 cannot overflow.
    const bool residual_applies = eye.have_residual && eye.residual_index == meta.index - 1;
    if (residual_applies) {
      // The design keeps only the reduced-size d_t: L_prev is recomputed from it, bit-identical to L_t.
      const cv::Mat previous_low_linear = upsampled_linear(eye.previous_low, full, link);
      const cv::Mat contrast = motion_contrast(previous_low_linear, alpha);      // Eq. 5
      const cv::Mat weight = motion_weight(contrast, config_.sensitivity);        // Eq. 6
      ResidualAddition added = add_weighted_residual(alpha, weight, eye.residual);  // Eq. 4
      wanted = added.alpha_prime;

      const ResidualSummary consumed = summarise_residual(eye.residual);
      out.stats.clipped_fraction = static_cast<double>(added.clipped) / samples;
      out.stats.dropped_sum = added.dropped_sum;
      out.stats.mean_motion_weight = mean_of(weight);
      out.stats.residual_applied = true;
      out.stats.residual_mean_abs = consumed.mean_abs;
      out.stats.residual_max_abs = consumed.max_abs;
      if (config_.record_stages) {
        stages.at(Stage::Residual) = eye.residual;
        stages.at(Stage::PreviousLowPass) = previous_low_linear;
        stages.at(Stage::Contrast) = contrast;
        stages.at(Stage::Weight) = weight;
        stages.at(Stage::AlphaUnclamped) = added.alpha_unclamped;
      }
    } else {
      // No full frame just before this one (stream start, lost frame, two reduced in a row): alpha alone.
      // U of values in [0, 1] stays in [0, 1], so the clamp only guards the convention.
      wanted = cv::max(cv::min(alpha, 1.0), 0.0);
    }
    // The residual serves exactly one reduced frame.
    eye.have_residual = false;
    eye.residual.release();
    eye.previous_low.release();
    if (config_.record_stages) {
      stages.at(Stage::Codes) = frame.codes;
      stages.at(Stage::Alpha) = alpha;
      stages.at(Stage::AlphaPrime) = wanted;
    }
  }

  if (config_.panel.has_history() && eye.previous_drive.empty()) {
    std::tie(eye.previous_wanted, eye.previous_drive) = held_history(wanted, config_.panel, config_.output_bits);
  }
  const cv::Mat previous_linear = eye.previous_wanted;
  const PanelDrive drive =
      drive_panel(wanted, previous_linear, eye.previous_drive, config_.panel, emission_, config_.output_bits);
  if (config_.panel.has_history()) {
    out.stats.lcd_unreachable_fraction = static_cast<double>(drive.unreachable_count) / samples;
    if (meta.parity == Parity::Full && drive.unreachable_count > 0) add_shortfall(eye.residual, drive.shortfall);
    eye.previous_wanted = config_.lcd_history == LcdHistory::Contributed ? drive.contributed : wanted;
    eye.previous_drive = dequantise(drive.codes, config_.output_bits);
    if (config_.record_stages) {
      stages.at(Stage::LcdTarget) = drive.target;
      stages.at(Stage::LcdPreviousDrive) = drive.previous_drive;
      stages.at(Stage::LcdPreviousLinear) = previous_linear;
      stages.at(Stage::LcdUnreachable) = drive.unreachable;
    }
  }

  if (meta.parity == Parity::Full) {
    const ResidualSummary kept = summarise_residual(eye.residual);
    out.stats.residual_mean_abs = kept.mean_abs;
    out.stats.residual_max_abs = kept.max_abs;
    if (config_.record_stages) stages.at(Stage::Residual) = eye.residual.clone();
  }

  out.wanted_linear = wanted;
  out.drive = drive.drive;
  out.drive_codes = drive.codes;
  out.emitted_linear = drive.emitted_linear;
  eye.last_output = out;
  if (config_.record_stages) {
    stages.at(Stage::Drive) = drive.codes;
    out.stages = std::move(stages);
  }
  return out;
}

}  // namespace trm
