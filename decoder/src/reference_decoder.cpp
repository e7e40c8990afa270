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

#include "frame_planes.hpp"
#include "view_arrival.hpp"

#include "trm/resample.hpp"
#include "trm/transfer.hpp"
#include "trm/vector_pow.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
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
std::vector<double> linear_of_codes(const EncoderConfig& link) {
  const int top = max_code(link.bits);
  std::vector<double> table(static_cast<std::size_t>(top) + 1);
  for (int code = 0; code <= top; ++code) {
    table[static_cast<std::size_t>(code)] = to_linear(static_cast<double>(code) / top, link.transfer);
  }
  return table;
}

// The upsampled low-pass frame in linear light, a row at a time: L_t = lin(U(d_t)) (Eq. 2) or alpha = lin(U(i_t))
// (Eq. 1). D and U act on encoded values by default (Sec. 4.2); in the linear resample space U acts on lin(d).
// The same doubles as U and to_linear on whole frames (upsample() is upsample_horizontal() and upsample_row()).
class UpsampledLinear {
 public:
  UpsampledLinear(const cv::Mat& reduced_codes, cv::Size full, const EncoderConfig& link)
      : full_(full), transfer_(link.transfer), encoded_space_(link.resample_space == ResampleSpace::Encoded) {
    const cv::Mat encoded = dequantise(reduced_codes, link.bits);
    horizontal_ = upsample_horizontal(encoded_space_ ? encoded : to_linear(encoded, link.transfer), full.width);
  }
  // Row y of the full-size frame into `out` (3 W doubles).
  void row(int y, double* out) const {
    upsample_row(horizontal_, y, full_.height, out);
    if (!encoded_space_) return;
    const auto samples = static_cast<std::size_t>(3 * full_.width);
    to_linear(std::span<const double>(out, samples), std::span<double>(out, samples), transfer_);
  }

 private:
  cv::Size full_;
  Transfer transfer_;
  bool encoded_space_;
  cv::Mat horizontal_;
};

// Sum / count in raster order (cv::mean multiplies by 1 / count, which can turn an all-ones mean into 1 - 1ulp).
double mean_of(const cv::Mat& single_channel) {
  double sum = 0.0;
  for (int y = 0; y < single_channel.rows; ++y) {
    const double* row = single_channel.ptr<double>(y);
    for (int x = 0; x < single_channel.cols; ++x) sum += row[x];
  }
  return sum / static_cast<double>(single_channel.total());
}

std::pair<double, double> summarise_residual(const cv::Mat& residual) {
  if (residual.empty()) return {0.0, 0.0};
  double sum = 0.0;
  double max_abs = 0.0;
  const cv::Mat flat = residual.reshape(1);
  for (int y = 0; y < flat.rows; ++y) {
    const double* row = flat.ptr<double>(y);
    // The sum in raster order, over the nonzero magnitudes only: adding +0 to a sum >= +0 leaves it as it is, and rho
    // is zero wherever beta was not clipped, so the chain of dependent additions is as long as the clipped samples.
    // The maximum (order-free: std::max never takes a NaN in) in a loop of its own, where it stays in a register.
    for (int k = 0; k < flat.cols; ++k) {
      const double magnitude = std::abs(row[k]);
      if (magnitude != 0.0) sum += magnitude;
    }
    double row_max = 0.0;
    for (int k = 0; k < flat.cols; ++k) row_max = std::max(row_max, std::abs(row[k]));
    max_abs = std::max(max_abs, row_max);
  }
  return {sum / static_cast<double>(flat.total()), max_abs};
}

// Every quantity of one view is computed a row at a time on OpenCV's threads: a sample depends only on its own
// inputs (and U's two source rows), so the doubles are the same for any split. Per-row counts and the values that
// clipping drops are kept per row and added up afterwards in raster order, the order of the statistics' sums.
struct RowTallies {
  std::vector<std::size_t> clipped;
  std::vector<std::size_t> unreachable;
  std::vector<std::vector<double>> dropped;  // |alpha + w rho - alpha'| of each clipped sample, in raster order
  std::vector<std::uint8_t> nan_drive;
  explicit RowTallies(int rows)
      : clipped(static_cast<std::size_t>(rows), 0),
        unreachable(static_cast<std::size_t>(rows), 0),
        dropped(static_cast<std::size_t>(rows)),
        nan_drive(static_cast<std::size_t>(rows), 0) {}
  static std::size_t total(const std::vector<std::size_t>& per_row) {
    std::size_t sum = 0;
    for (const std::size_t count : per_row) sum += count;
    return sum;
  }
};

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
    : config_((config.validate(), std::move(config))), emission_(config_.panel, config_.output_bits) {
  if (!config_.report_planes && !config_.panel.has_history()) oled_codes_.emplace(config_.panel.oled, config_.output_bits);
  const int top = max_code(config_.output_bits);
  drive_value_of_code_.resize(static_cast<std::size_t>(top) + 1);
  for (int code = 0; code <= top; ++code) {
    drive_value_of_code_[static_cast<std::size_t>(code)] = dequantise(static_cast<std::uint16_t>(code), top);
  }
}

DecodedFrame ReferenceDecoder::decode_lost(const FrameMeta& meta) {
  detail::check_lost_view(meta, "ReferenceDecoder");
  EyeState& eye = eyes_[meta.eye];
  DecodedFrame out = detail::hold_lost_view(eye, meta, config_.report_planes);
  eye.previous_low_linear.release();
  return out;
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
  const int row_len = 3 * full.width;
  const bool record = config_.record_stages;
  const bool is_full = meta.parity == Parity::Full;
  const Panel& panel = config_.panel;
  const bool history = panel.has_history();
  const int top = max_code(config_.output_bits);

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
  RowTallies tallies(full.height);

  // LCD history: v_{t-1} and x_{t-1}. The first frame of an eye has none: the panel is taken to have held this same
  // frame, x_{t-1} = x_t and v_{t-1} = the held drive of x_t (M(v, v) = x_t^(1/gamma)), quantised as any shown drive.
  const bool first_lcd_frame = history && eye.previous_drive.empty();

  // x_t: what this frame should add to the pair, in linear light, within [0, 1]; then the panel drive of it.
  // Every sample of these planes is written below, so they may be the planes of an earlier view that nothing holds.
  // Without the report planes, x_t and v_t are rows of scratch (x_t stays a plane where the stages record it, where
  // the LCD keeps it as the next x_{t-1}, and on the LCD's first frame, which reads it as x_{t-1}; an OLED's v_t is not
  // computed at all, its codes come from OledDriveCodes) and the emitted light is not computed.
  const auto plane = [&eye](int type) { return detail::reusable_plane(eye.spare_planes, eye.full_size, type); };
  const bool planes = config_.report_planes;
  const bool wanted_kept =
      planes || record || (history && (first_lcd_frame || config_.lcd_history == LcdHistory::Wanted));
  cv::Mat wanted = wanted_kept ? plane(CV_64FC3) : cv::Mat();
  cv::Mat drive = planes ? plane(CV_64FC3) : cv::Mat();
  cv::Mat codes = plane(CV_16UC3);
  cv::Mat emitted = planes ? plane(CV_64FC3) : cv::Mat();
  // Row y of a plane, or of a thread's scratch where the view keeps no plane.
  const auto row_of = [row_len](cv::Mat& m, std::vector<double>& scratch, int y) {
    if (!m.empty()) return m.ptr<double>(y);
    scratch.resize(static_cast<std::size_t>(row_len));
    return scratch.data();
  };

  cv::Mat previous_drive = first_lcd_frame ? plane(CV_64FC3) : eye.previous_drive;
  const cv::Mat previous_wanted = first_lcd_frame ? wanted : eye.previous_wanted;
  cv::Mat next_drive;   // v_t as shown, the v_{t-1} of the next frame
  cv::Mat contributed;  // LcdHistory::Contributed: x_t where reachable, x_t_eff where not
  cv::Mat lcd_target;
  cv::Mat lcd_unreachable;
  if (history) {
    next_drive = plane(CV_64FC3);
    if (config_.lcd_history == LcdHistory::Contributed) contributed = plane(CV_64FC3);
    if (record) {
      lcd_target.create(full, CV_64FC3);
      lcd_unreachable = cv::Mat::zeros(full, CV_8UC3);
    }
  }

  // The panel inverse of row y of `wanted` (DESIGN §4, Sec. 4.4). With history (LCD, Eq. 7) the pair
  // (v_{t-1}, v_t) is seen as M(v_t, v_{t-1}); to add x_t after a frame that contributed x_{t-1} the pair must merge
  // to m, with v_{t-1} the drive actually shown. Unreachable m: for a full frame the linear shortfall
  // x_t - x_t_eff joins rho (`residual_row`, null otherwise) and the next reduced frame makes it up (paper Sec. 4.4).
  // It uses the unquantised v_t: drive quantisation error is never fed back (DESIGN §3).
  //
  // With LcdHistory::Contributed, x_t_eff rather than x_t is what the next frame's target builds on: the next pair is
  // wanted to average (x_{t+1} + x_t_eff) / 2, and with x_{t+1} = alpha + rho + shortfall that is (alpha + beta) / 2
  // = I for static content. Building on the wanted x_t instead would count the shortfall twice (it is already in
  // rho), leaving the pair shortfall / 2 too bright. Where m was reachable x_t_eff = x_t, so x_t is kept bit for bit.
  // The design's rule (LcdHistory::Wanted, the default) builds on the wanted x_t, as independent implementations do.
  const auto drive_row = [&](int y, const double* x_row, double* v_row, double* residual_row) {
    std::uint16_t* q_row = codes.ptr<std::uint16_t>(y);
    double* e_row = planes ? emitted.ptr<double>(y) : nullptr;
    if (oled_codes_) {
      // OLED without the drive plane: the codes alone, from where each code begins (the same integers as the pow).
      const auto n = static_cast<std::size_t>(row_len);
      if (!oled_codes_->codes(std::span<const double>(x_row, n), std::span<std::uint16_t>(q_row, n))) {
        tallies.nan_drive[static_cast<std::size_t>(y)] = 1;
      }
      return;
    }
    if (!history) {
      // OLED: v = x^(1/gamma_c), the row's pows a vector at a time (the same doubles as panel.drive per sample).
      panel.oled.drive(std::span<const double>(x_row, static_cast<std::size_t>(row_len)),
                       std::span<double>(v_row, static_cast<std::size_t>(row_len)));
      bool nan = false;
      for (int k = 0; k < row_len; ++k) {
        const double v = v_row[k];
        nan |= std::isnan(v);
        q_row[k] = std::isnan(v) ? std::uint16_t{0} : quantise(v, top);
      }
      if (nan) tallies.nan_drive[static_cast<std::size_t>(y)] = 1;
      if (e_row != nullptr) {
        emission_.row(std::span<const std::uint16_t>(q_row, static_cast<std::size_t>(row_len)),
                      std::span<double>(e_row, static_cast<std::size_t>(row_len)));
      }
      return;
    }
    const double* xp_row = previous_wanted.ptr<double>(y);
    double* vp_row = previous_drive.ptr<double>(y);
    if (first_lcd_frame) {
      for (int k = 0; k < row_len; ++k) {
        vp_row[k] = dequantise(quantise(panel.drive_from_linear(x_row[k], k % 3), top), top);
      }
    }
    // The LCD drive of the row a chunk at a time (the same doubles as panel.drive per sample); the shown drive v_t as
    // the next frame's v_{t-1} by each code's value (dequantise's doubles, without a division per sample).
    constexpr int kChunk = 255;
    std::array<PanelDriveSample, kChunk> samples;
    double* next_row = next_drive.ptr<double>(y);
    double* target_row = record ? lcd_target.ptr<double>(y) : nullptr;
    double* contributed_row = contributed.empty() ? nullptr : contributed.ptr<double>(y);
    std::uint8_t* unreachable_row = record ? lcd_unreachable.ptr<std::uint8_t>(y) : nullptr;
    const double* value_of_code = drive_value_of_code_.data();
    bool nan = false;
    std::size_t unreachable = 0;
    for (int start = 0; start < row_len; start += kChunk) {
      const auto count = static_cast<std::size_t>(std::min(kChunk, row_len - start));
      panel.lcd.drive(std::span<const double>(x_row + start, count), std::span<const double>(xp_row + start, count),
                      std::span<const double>(vp_row + start, count), std::span<PanelDriveSample>(samples.data(), count));
      for (std::size_t i = 0; i < count; ++i) {
        const auto k = static_cast<std::size_t>(start) + i;
        const PanelDriveSample& sample = samples[i];
        const double x_t = x_row[k];
        v_row[k] = sample.v;
        nan |= std::isnan(sample.v);
        q_row[k] = std::isnan(sample.v) ? std::uint16_t{0} : quantise(sample.v, top);
        next_row[k] = value_of_code[q_row[k]];
        if (target_row != nullptr) target_row[k] = sample.target;
        if (contributed_row != nullptr) contributed_row[k] = sample.reachable ? x_t : sample.contributed;
        if (sample.reachable) continue;
        ++unreachable;
        if (unreachable_row != nullptr) unreachable_row[k] = 255;
        if (residual_row != nullptr) residual_row[k] += x_t - sample.contributed;
      }
    }
    if (nan) tallies.nan_drive[static_cast<std::size_t>(y)] = 1;
    tallies.unreachable[static_cast<std::size_t>(y)] = unreachable;
    if (e_row == nullptr) return;
    // The light of each code after the previous one in a pass of its own, so that the table's loads (512 KiB at
    // 8-bit output, more than a core's L2) are in flight together.
    for (int k = 0; k < row_len; ++k) {
      const auto previous_code = static_cast<std::uint16_t>(std::lround(vp_row[k] * top));
      e_row[k] = emission_(q_row[k], previous_code, k % 3);
    }
  };

  if (is_full) {
    // Full frame t (Eq. 2, Sec. 4.2): d_t = Q_b(D(E_t)) as the encoder sends it, L_t = lin(U(d_t)),
    // I_t = lin(E_t), beta = 2 I_t - L_t; shown = clamp(beta, 0, 1) and rho_t = beta - shown, which the next
    // reduced frame makes up for. A lost line (concealment) has no trustworthy beta: it shows L_t (within [0, 1],
    // so its rho is 0).
    const cv::Mat low_codes = reduce_codes(frame.codes, link);
    const UpsampledLinear low(low_codes, full, link);
    const std::vector<double> linear_of_code = linear_of_codes(link);
    cv::Mat low_linear = plane(CV_64FC3);
    cv::Mat residual = plane(CV_64FC3);
    cv::Mat full_linear = record ? cv::Mat(full, CV_64FC3) : cv::Mat();
    cv::Mat beta = record ? cv::Mat(full, CV_64FC3) : cv::Mat();
    cv::parallel_for_(cv::Range(0, full.height), [&](const cv::Range& rows) {
      std::vector<double> wanted_scratch;
      std::vector<double> drive_scratch;
      for (int y = rows.start; y < rows.end; ++y) {
        double* l_row = low_linear.ptr<double>(y);
        low.row(y, l_row);
        const std::uint16_t* c_row = frame.codes.ptr<std::uint16_t>(y);
        const bool intact = static_cast<std::size_t>(y) >= line_intact.size() || line_intact[static_cast<std::size_t>(y)];
        double* x_row = row_of(wanted, wanted_scratch, y);
        double* r_row = residual.ptr<double>(y);
        std::size_t clipped = 0;
        for (int k = 0; k < row_len; ++k) {
          const double linear = linear_of_code[c_row[k]];
          const double b = intact ? 2.0 * linear - l_row[k] : l_row[k];  // Eq. 2
          if (record) {
            full_linear.ptr<double>(y)[k] = linear;
            beta.ptr<double>(y)[k] = b;
          }
          const double shown = std::clamp(b, 0.0, 1.0);
          x_row[k] = shown;
          r_row[k] = b - shown;
          clipped += shown != b ? 1 : 0;
        }
        tallies.clipped[static_cast<std::size_t>(y)] = clipped;
        drive_row(y, x_row, row_of(drive, drive_scratch, y), r_row);
      }
    });
    out.stats.clipped_fraction = static_cast<double>(RowTallies::total(tallies.clipped)) / samples;
    eye.have_residual = true;
    eye.residual_index = meta.index;
    eye.residual = residual;
    eye.previous_low = low_codes;
    // The design keeps only the reduced-size d_t and recomputes L_t from it for the next reduced frame's motion
    // test; the reference keeps L_t itself, the same doubles.
    eye.previous_low_linear = low_linear;
    if (record) {
      stages.at(Stage::Codes) = frame.codes;
      stages.at(Stage::Reduced) = low_codes;
      stages.at(Stage::LowPass) = low_linear;
      stages.at(Stage::Linear) = full_linear;
      stages.at(Stage::Beta) = beta;
      stages.at(Stage::Shown) = wanted;
    }
  } else {
    // Reduced frame t + 1: alpha = lin(U(i)) (Eq. 1). With the residual of full frame t:
    // c = |Y(L_t) - Y(alpha)| / (Y(L_t) + Y(alpha)) on Rec. 709 luma (Eq. 5; 0 where both are black: nothing moved
    // that could be seen), w = exp(-s c) (Eq. 6; exactly 1 where c = 0, so static content gets the whole residual
    // even for s = +inf, where s c would be inf * 0 = NaN), alpha' = clamp(alpha + w rho, 0, 1) (Eq. 4), one w per
    // pixel shared by the channels. What the clamp drops is lost for good: the residual serves one reduced frame.
    const UpsampledLinear alpha_rows(frame.codes, full, link);
    // meta.index >= 0 (check_link_frame), so index - 1 cannot overflow.
    const bool residual_applies = eye.have_residual && eye.residual_index == meta.index - 1;
    cv::Mat alpha = record ? cv::Mat(full, CV_64FC3) : cv::Mat();
    cv::Mat weight = residual_applies ? plane(CV_64FC1) : cv::Mat();
    cv::Mat contrast = residual_applies && record ? cv::Mat(full, CV_64FC1) : cv::Mat();
    cv::Mat alpha_unclamped = residual_applies && record ? cv::Mat(full, CV_64FC3) : cv::Mat();
    const double s = config_.sensitivity;
    cv::parallel_for_(cv::Range(0, full.height), [&](const cv::Range& rows) {
      std::vector<double> alpha_buffer(record ? 0 : static_cast<std::size_t>(row_len));
      std::vector<double> contrast_row;
      std::vector<double> wanted_scratch;
      std::vector<double> drive_scratch;
      for (int y = rows.start; y < rows.end; ++y) {
        double* a_row = record ? alpha.ptr<double>(y) : alpha_buffer.data();
        alpha_rows.row(y, a_row);
        double* x_row = row_of(wanted, wanted_scratch, y);
        double* v_row = row_of(drive, drive_scratch, y);
        if (!residual_applies) {
          // No full frame just before this one (stream start, lost frame, two reduced in a row): alpha alone.
          // U of values in [0, 1] stays in [0, 1], so the clamp only guards the convention.
          for (int k = 0; k < row_len; ++k) x_row[k] = std::max(std::min(a_row[k], 1.0), 0.0);
          drive_row(y, x_row, v_row, nullptr);
          continue;
        }
        const double* p_row = eye.previous_low_linear.ptr<double>(y);
        const double* r_row = eye.residual.ptr<double>(y);
        double* w_row = weight.ptr<double>(y);
        std::vector<double>& dropped = tallies.dropped[static_cast<std::size_t>(y)];
        std::size_t clipped = 0;
        // Eq. 5 per pixel, then Eq. 6's exp over the row a vector at a time (exp_elements: std::exp's doubles).
        contrast_row.resize(static_cast<std::size_t>(full.width));
        for (int x = 0; x < full.width; ++x) {
          const double* p = p_row + 3 * x;
          const double* a = a_row + 3 * x;
          const double y_prev = kLumaR * p[0] + kLumaG * p[1] + kLumaB * p[2];
          const double y_alpha = kLumaR * a[0] + kLumaG * a[1] + kLumaB * a[2];
          const double sum = y_prev + y_alpha;
          const double c = sum > 0.0 ? std::abs(y_prev - y_alpha) / sum : 0.0;  // Eq. 5
          contrast_row[static_cast<std::size_t>(x)] = c;
          w_row[x] = -s * c;
          if (record) contrast.ptr<double>(y)[x] = c;
        }
        const auto pixels = static_cast<std::size_t>(full.width);
        exp_elements(std::span<const double>(w_row, pixels), std::span<double>(w_row, pixels));
        for (int x = 0; x < full.width; ++x) {
          // Eq. 6; exactly 1 where c = 0 (for s = inf, -s c is NaN there).
          const double w = contrast_row[static_cast<std::size_t>(x)] == 0.0 ? 1.0 : w_row[x];
          w_row[x] = w;
          for (int ch = 0; ch < 3; ++ch) {
            const int k = 3 * x + ch;
            const double added = a_row[k] + w * r_row[k];  // Eq. 4
            const double kept = std::clamp(added, 0.0, 1.0);
            if (record) alpha_unclamped.ptr<double>(y)[k] = added;
            x_row[k] = kept;
            if (kept != added) {
              ++clipped;
              dropped.push_back(std::abs(added - kept));
            }
          }
        }
        tallies.clipped[static_cast<std::size_t>(y)] = clipped;
        drive_row(y, x_row, v_row, nullptr);
      }
    });
    if (residual_applies) {
      double dropped_sum = 0.0;
      for (const std::vector<double>& row : tallies.dropped) {
        for (const double value : row) dropped_sum += value;
      }
      out.stats.clipped_fraction = static_cast<double>(RowTallies::total(tallies.clipped)) / samples;
      out.stats.dropped_sum = dropped_sum;
      out.stats.mean_motion_weight = mean_of(weight);
      out.stats.residual_applied = true;
      out.stats.residual_mean_abs = eye.residual_mean_abs;  // of the rho consumed
      out.stats.residual_max_abs = eye.residual_max_abs;
      if (record) {
        stages.at(Stage::Residual) = eye.residual;
        stages.at(Stage::PreviousLowPass) = eye.previous_low_linear;
        stages.at(Stage::Contrast) = contrast;
        stages.at(Stage::Weight) = weight;
        stages.at(Stage::AlphaUnclamped) = alpha_unclamped;
      }
    }
    // The residual serves exactly one reduced frame.
    eye.have_residual = false;
    eye.residual.release();
    eye.previous_low.release();
    eye.previous_low_linear.release();
    if (record) {
      stages.at(Stage::Codes) = frame.codes;
      stages.at(Stage::Alpha) = alpha;
      stages.at(Stage::AlphaPrime) = wanted;
    }
  }

  for (const std::uint8_t nan : tallies.nan_drive) {
    if (nan) throw std::invalid_argument("ReferenceDecoder: the panel drive is NaN");
  }
  if (history) {
    const std::size_t unreachable = RowTallies::total(tallies.unreachable);
    out.stats.lcd_unreachable_fraction = static_cast<double>(unreachable) / samples;
    if (record) {
      stages.at(Stage::LcdTarget) = lcd_target;
      stages.at(Stage::LcdPreviousDrive) = previous_drive;
      stages.at(Stage::LcdPreviousLinear) = first_lcd_frame ? wanted.clone() : previous_wanted;
      stages.at(Stage::LcdUnreachable) = lcd_unreachable;
    }
    eye.previous_wanted = config_.lcd_history == LcdHistory::Contributed ? contributed : wanted;
    eye.previous_drive = next_drive;
  }

  if (is_full) {
    // rho as kept for the next reduced frame (with the LCD shortfall, added in the row pass); the reduced frame
    // reports the same summary of the rho it consumes.
    std::tie(eye.residual_mean_abs, eye.residual_max_abs) = summarise_residual(eye.residual);
    out.stats.residual_mean_abs = eye.residual_mean_abs;
    out.stats.residual_max_abs = eye.residual_max_abs;
    if (record) stages.at(Stage::Residual) = eye.residual.clone();
  }

  if (planes) out.wanted_linear = wanted;
  out.drive = drive;
  out.drive_codes = codes;
  out.emitted_linear = emitted;
  eye.last_output = out;
  if (record) {
    stages.at(Stage::Drive) = codes;
    out.stages = std::move(stages);
  }
  return out;
}

}  // namespace trm
