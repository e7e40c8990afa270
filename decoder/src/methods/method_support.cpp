#include "method_support.hpp"

#include "trm/resample.hpp"
#include "trm/transfer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace trm::methods {

PanelShow::PanelShow(const DecoderConfig& config)
    : config_(config), emission_((config_.validate(), config_.panel), config_.output_bits) {
  if (!config_.report_planes && !config_.panel.has_history()) oled_codes_.emplace(config_.panel.oled, config_.output_bits);
}

// An OLED's drive codes without the drive plane (DecoderConfig::report_planes = false): the same integers as quantise()
// of the plane, and its refusal of NaN.
cv::Mat PanelShow::oled_codes_of(const cv::Mat& wanted) const {
  cv::Mat codes(wanted.size(), CV_16UC3);
  const auto n = static_cast<std::size_t>(3 * wanted.cols);
  for (int y = 0; y < wanted.rows; ++y) {
    if (!oled_codes_->codes(std::span<const double>(wanted.ptr<double>(y), n),
                            std::span<std::uint16_t>(codes.ptr<std::uint16_t>(y), n))) {
      throw std::invalid_argument("quantise: NaN value");
    }
  }
  return codes;
}

DecodedFrame PanelShow::show(const FrameMeta& meta, const cv::Mat& wanted) {
  if (oled_codes_) return emit(meta, cv::Mat(), cv::Mat(), oled_codes_of(wanted));
  cv::Mat drive(wanted.size(), CV_64FC3);
  for (int y = 0; y < wanted.rows; ++y) {
    const auto* x_row = wanted.ptr<cv::Vec3d>(y);
    auto* v_row = drive.ptr<cv::Vec3d>(y);
    for (int x = 0; x < wanted.cols; ++x) {
      for (int ch = 0; ch < 3; ++ch) v_row[x][ch] = config_.panel.drive_from_linear(x_row[x][ch], ch);
    }
  }
  cv::Mat codes = quantise(drive, config_.output_bits);
  if (!config_.report_planes) return emit(meta, cv::Mat(), cv::Mat(), std::move(codes));
  return emit(meta, wanted.clone(), std::move(drive), std::move(codes));
}

DecodedFrame PanelShow::show_received(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) {
  check_received(frame, config_, "display method");
  if (frame.meta.parity != Parity::Full) {
    throw std::invalid_argument("display method: expected a full view, got a reduced one (t=" +
                                std::to_string(frame.meta.index) + ")");
  }
  if (line_intact.empty()) return show(frame.meta, linear_of_codes(frame.codes, frame.meta));
  cv::Mat codes = frame.codes.clone();
  const int concealed = conceal_lost_rows(codes, line_intact);
  DecodedFrame out = show(frame.meta, linear_of_codes(codes, frame.meta));
  out.stats.concealed_lines = concealed;
  return out;
}

DecodedFrame PanelShow::hold(const FrameMeta& meta) {
  const auto last = last_.find(meta.eye);
  if (last == last_.end() || last->second.drive_codes.size() != cv::Size(meta.full_width, meta.full_height)) {
    return black(meta);
  }
  const DecodedFrame& previous = last->second;
  return emit(meta, previous.wanted_linear.clone(), previous.drive.clone(), previous.drive_codes.clone());
}

DecodedFrame PanelShow::black(const FrameMeta& meta) {
  const cv::Size full(meta.full_width, meta.full_height);
  const auto zero_plane = [&] { return config_.report_planes ? cv::Mat::zeros(full, CV_64FC3) : cv::Mat(); };
  return emit(meta, zero_plane(), zero_plane(), cv::Mat::zeros(full, CV_16UC3));
}

DecodedFrame PanelShow::lost(const FrameMeta& meta) {
  check_view_meta(meta, "display method: lost view: ");
  const auto last = last_.find(meta.eye);
  const bool have = last != last_.end() && last->second.drive_codes.size() == cv::Size(meta.full_width, meta.full_height);
  DecodedFrame out = have ? hold(meta) : black(meta);
  out.stats.frame_lost = true;
  out.stats.concealed_lines = meta.height;
  return out;
}

DecodedFrame PanelShow::emit(const FrameMeta& meta, cv::Mat wanted, cv::Mat drive, cv::Mat codes) {
  DecodedFrame out;
  out.meta = shown_meta(meta);
  out.wanted_linear = std::move(wanted);
  out.drive = std::move(drive);
  out.drive_codes = std::move(codes);
  // A panel with history merges frame t with the codes of frame t-1 (the first frame of an eye as if held).
  const auto last = last_.find(meta.eye);
  const bool have_previous = last != last_.end() && last->second.drive_codes.size() == out.drive_codes.size();
  const cv::Mat& previous = have_previous ? last->second.drive_codes : out.drive_codes;
  if (config_.report_planes) out.emitted_linear.create(out.drive_codes.size(), CV_64FC3);
  for (int y = 0; y < out.emitted_linear.rows; ++y) {
    const auto* q_row = out.drive_codes.ptr<cv::Vec3w>(y);
    const auto* p_row = previous.ptr<cv::Vec3w>(y);
    auto* e_row = out.emitted_linear.ptr<cv::Vec3d>(y);
    for (int x = 0; x < out.drive_codes.cols; ++x) {
      for (int ch = 0; ch < 3; ++ch) e_row[x][ch] = emission_(q_row[x][ch], p_row[x][ch], ch);
    }
  }
  last_[meta.eye] = out;
  return out;
}

void check_received(const LinkFrame& frame, const DecoderConfig& config, const char* method) {
  const FrameMeta& meta = frame.meta;
  const std::string where = std::string(method) + ": view t=" + std::to_string(meta.index) + " eye " +
                            std::to_string(meta.eye) + ": ";
  check_view_meta(meta, where);
  if (meta.bits != config.link.bits || meta.transfer != config.link.transfer) {
    throw std::invalid_argument(where + "sent with " + std::to_string(meta.bits) + " bits, " + to_string(meta.transfer) +
                                "; the display expects " + std::to_string(config.link.bits) + " bits, " +
                                to_string(config.link.transfer));
  }
  if (frame.codes.type() != CV_16UC3 || frame.codes.cols != meta.width || frame.codes.rows != meta.height) {
    throw std::invalid_argument(where + "codes must be CV_16UC3 of " + std::to_string(meta.width) + "x" +
                                std::to_string(meta.height));
  }
  const int highest = highest_code(frame.codes);
  if (highest > std::ldexp(1.0, meta.bits) - 1.0) {
    throw std::invalid_argument(where + "code " + std::to_string(highest) + " exceeds " +
                                std::to_string(meta.bits) + " bits");
  }
}

FullViewSender::FullViewSender(const EncoderConfig& link, bool every_slot) : encoder_(link), every_slot_(every_slot) {}

bool FullViewSender::sends(std::int64_t t, int eye) const {
  return every_slot_ || parity_of(t, eye, encoder_.config()) == Parity::Full;
}

Transmission FullViewSender::send(const cv::Mat& linear, std::int64_t t, int eye) {
  Transmission out;
  out.frame = encoder_.encode_as(Parity::Full, linear, t, eye);
  out.pixels_rendered = static_cast<std::int64_t>(out.frame.codes.total());
  return out;
}

TrmFrameDisplay::TrmFrameDisplay(const std::string& impl, const FixedDecoderConfig& config)
    : decoder_(make_decoder(impl, config)) {}

DecodedFrame TrmFrameDisplay::show(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) {
  return line_intact.empty() ? decoder_->decode(frame) : decoder_->decode(frame, line_intact);
}

DecodedFrame TrmFrameDisplay::show_lost(const FrameMeta& slot) { return decoder_->decode_lost(slot); }

DecodedFrame TrmFrameDisplay::show_unsent(const FrameMeta&) {
  throw std::logic_error("a TRM-frame method sends every view");
}

FrameMeta FullViewSender::view_meta(std::int64_t t, int eye, cv::Size full) const {
  return view_meta_of(t, eye, Parity::Full, full, full, encoder_.config());
}

FrameMeta trm_view_meta(std::int64_t t, int eye, cv::Size full, const EncoderConfig& link) {
  const Parity parity = parity_of(t, eye, link);
  const cv::Size sent = parity == Parity::Full ? full
                                               : cv::Size(reduced_size(full.width, link.reduction),
                                                          reduced_size(full.height, link.reduction));
  return view_meta_of(t, eye, parity, sent, full, link);
}

namespace {

class PlainFrameDisplay : public MethodDisplay {
 public:
  PlainFrameDisplay(const DecoderConfig& config, Between between) : panel_(config), between_(between) {}
  DecodedFrame show(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) override {
    return panel_.show_received(frame, line_intact);
  }
  DecodedFrame show_lost(const FrameMeta& slot) override { return panel_.lost(slot); }
  DecodedFrame show_unsent(const FrameMeta& slot) override {
    switch (between_) {
      case Between::Repeat: return panel_.hold(slot);
      case Between::Black: return panel_.black(slot);
      case Between::Nothing: break;
    }
    throw std::logic_error("a method that sends every view was asked for an unsent one");
  }

 private:
  PanelShow panel_;
  Between between_;
};

}  // namespace

std::unique_ptr<MethodDisplay> plain_frame_display(const DecoderConfig& config, Between between) {
  return std::make_unique<PlainFrameDisplay>(config, between);
}

DisplayMethod trm_frame_method(std::string name, std::string summary, SenderFactory sender, HeadsetConfig headset) {
  DisplayMethod m;
  m.name = std::move(name);
  m.summary = std::move(summary);
  m.fixed_point = true;
  m.make_sender = [sender](const MethodSetup& setup) { return sender(setup.decoder.decoder.link); };
  m.make_display = [headset](const MethodSetup& setup) -> std::unique_ptr<MethodDisplay> {
    return std::make_unique<TrmFrameDisplay>(setup.impl, headset(setup.decoder));
  };
  return m;
}

DisplayMethod plain_frame_method(std::string name, std::string summary, Between between) {
  DisplayMethod m;
  m.name = std::move(name);
  m.summary = std::move(summary);
  m.make_sender = [between](const MethodSetup& setup) -> std::unique_ptr<MethodSender> {
    return std::make_unique<FullViewSender>(setup.decoder.decoder.link, between == Between::Nothing);
  };
  m.make_display = [between](const MethodSetup& setup) { return plain_frame_display(setup.decoder.decoder, between); };
  return m;
}

cv::Mat linear_of_codes(const cv::Mat& codes, const FrameMeta& meta) {
  return to_linear(dequantise(codes, meta.bits), meta.transfer);
}

int conceal_lost_rows(cv::Mat& codes, std::span<const std::uint8_t> line_intact) {
  if (line_intact.size() != static_cast<std::size_t>(codes.rows)) {
    throw std::invalid_argument("display method: line mask has " + std::to_string(line_intact.size()) +
                                " entries for a view of " + std::to_string(codes.rows) + " lines");
  }
  int first_intact = -1;
  for (int y = 0; y < codes.rows && first_intact < 0; ++y) {
    if (line_intact[static_cast<std::size_t>(y)]) first_intact = y;
  }
  if (first_intact < 0) throw std::invalid_argument("display method: a view with no intact line is a lost view");
  int concealed = 0;
  for (int y = 0; y < codes.rows; ++y) {
    if (line_intact[static_cast<std::size_t>(y)]) continue;
    // Rows above y are already concealed, so the row just above holds the nearest intact row above.
    codes.row(y > first_intact ? y - 1 : first_intact).copyTo(codes.row(y));
    ++concealed;
  }
  return concealed;
}

FrameMeta shown_meta(const FrameMeta& sent) {
  FrameMeta meta = sent;
  meta.width = sent.full_width;
  meta.height = sent.full_height;
  return meta;
}

}  // namespace trm::methods
