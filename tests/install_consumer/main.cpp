// Encodes one frame pair of a built-in scene with the installed encoder, decodes it with the installed fixed-point
// decoders and the reference, and checks what the design guarantees: the full view's codes are the link quantisation
// of the scene's sRGB encoding (computed here from IEC 61966-2-1, not by trm), the reduced view has the reduced size
// of DESIGN §3, the streaming and frame-at-a-time fixed-point decoders agree bit for bit, and the fixed-point output
// meets DESIGN §6 against the reference; the drive codes written as a PNG through the installed media plugin read
// back the same. Exit status 0 only when all of it holds.
#include "trm/decoder.hpp"
#include "trm/encoder.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/media.hpp"
#include "trm/metrics.hpp"
#include "trm/scene.hpp"

#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <vector>

namespace {

int failures = 0;

void check(bool ok, const char* what) {
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what);
  if (!ok) ++failures;
}

double srgb_encode(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

// The codes are floor(enc(x) 255 + 1/2); where enc(x) 255 lies within float noise of a half code, either neighbour.
bool codes_are_link_quantisation(const cv::Mat& linear, const cv::Mat& codes) {
  for (int y = 0; y < linear.rows; ++y) {
    for (int x = 0; x < linear.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double scaled = srgb_encode(linear.at<cv::Vec3d>(y, x)[c]) * 255.0;
        const double expected = std::floor(scaled + 0.5);
        const double code = codes.at<cv::Vec3w>(y, x)[c];
        const bool near_half = std::abs(scaled - std::floor(scaled) - 0.5) < 1e-9;
        if (code != expected && !(near_half && std::abs(code - expected) <= 1.0)) return false;
      }
    }
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer PNG_PATH\n");
    return 2;
  }
  const int width = 64, height = 48;
  trm::SceneParams params;
  params.width = width;
  params.height = height;
  const std::unique_ptr<trm::FrameSource> scene = trm::make_scene("discs", params);

  trm::FixedDecoderConfig config;  // the library defaults: r = 1/2, 8-bit link and drive, OLED
  const trm::TrmEncoder encoder(config.decoder.link);
  const std::unique_ptr<trm::HeadsetDecoder> streaming = trm::make_decoder("fixed", config);
  const std::unique_ptr<trm::HeadsetDecoder> frame_at_a_time = trm::make_decoder("fixed-frame", config);
  const std::unique_ptr<trm::HeadsetDecoder> reference = trm::make_decoder("reference", config);

  trm::CodeAgreement against_reference;
  bool streaming_equals_frame = true;
  cv::Mat last_codes;
  for (std::int64_t t = 0; t < 2; ++t) {
    const cv::Mat linear = scene->linear_frame(t);
    const trm::LinkFrame view = encoder.encode(linear, t);
    if (t == 0) {
      check(view.meta.parity == trm::Parity::Full && view.codes.size() == cv::Size(width, height),
            "frame 0 is sent as a full view");
      check(codes_are_link_quantisation(linear, view.codes), "full view codes are Q_8(sRGB(x))");
    } else {
      // w = max(1, floor(r W + 1/2)) at r = 1/2
      check(view.meta.parity == trm::Parity::Reduced && view.codes.size() == cv::Size(32, 24),
            "frame 1 is sent as a 32x24 reduced view");
    }
    const trm::DecodedFrame a = streaming->decode(view);
    const trm::DecodedFrame b = frame_at_a_time->decode(view);
    const trm::DecodedFrame r = reference->decode(view);
    check(a.drive_codes.size() == cv::Size(width, height), "decoded at the full view size");
    streaming_equals_frame = streaming_equals_frame && cv::norm(a.drive_codes, b.drive_codes, cv::NORM_INF) == 0.0;
    against_reference += trm::compare_codes(a.drive_codes, r.drive_codes);
    last_codes = a.drive_codes;
  }
  check(trm::media::write_image(argv[1], last_codes), "drive codes written as a PNG through the media plugin");
  const cv::Mat read_back = trm::media::read_image(argv[1], -1);  // cv::IMREAD_UNCHANGED
  check(read_back.type() == last_codes.type() && read_back.size() == last_codes.size() &&
            cv::norm(read_back, last_codes, cv::NORM_INF) == 0.0,
        "the PNG reads back as the same codes");
  check(streaming_equals_frame, "streaming and frame-at-a-time fixed-point decoders agree bit for bit");
  check(trm::kReferenceAgreementCriterion.met_by(against_reference), "fixed point meets DESIGN 6 against the reference");
  std::printf("%lld of %lld codes identical to the reference, max %g LSB\n",
              static_cast<long long>(against_reference.identical), static_cast<long long>(against_reference.compared),
              against_reference.max_lsb);
  return failures == 0 ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "install consumer: %s\n", e.what());
  return 1;
}
