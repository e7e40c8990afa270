#include "trm/jpegls.hpp"

#include <charls/charls.h>

#include <string>

namespace trm::link {

namespace {

void check_bits(int bits) {
  if (bits != 8 && bits != 10) throw std::invalid_argument("JPEG-LS: link bits must be 8 or 10, got " + std::to_string(bits));
}

}  // namespace

std::vector<std::uint8_t> jpegls_encode(const cv::Mat& codes, int bits) {
  check_bits(bits);
  if (codes.type() != CV_16UC3 || codes.empty() || codes.cols > 0xFFFF || codes.rows > 0xFFFF)
    throw std::invalid_argument("JPEG-LS: expected non-empty CV_16UC3 codes of at most 65535 x 65535");
  const int max_code = highest_code(codes);
  if (max_code >= (1 << bits))
    throw std::invalid_argument("JPEG-LS: code " + std::to_string(max_code) + " does not fit " +
                                std::to_string(bits) + " bits");

  // CharLS takes samples of up to 8 bits as bytes and of 9-16 bits as native 16-bit words.
  cv::Mat source;
  if (bits == 8) codes.convertTo(source, CV_8UC3);
  else source = codes.isContinuous() ? codes : codes.clone();
  if (!source.isContinuous()) source = source.clone();

  try {
    charls::jpegls_encoder encoder;
    encoder.frame_info({static_cast<std::uint32_t>(codes.cols), static_cast<std::uint32_t>(codes.rows), bits, 3})
        .interleave_mode(charls::interleave_mode::sample)
        .near_lossless(0);
    std::vector<std::uint8_t> out(encoder.estimated_destination_size());
    encoder.destination(out);
    const std::size_t written = encoder.encode(source.data, source.total() * source.elemSize());
    out.resize(written);
    return out;
  } catch (const std::exception& e) {
    throw JpegLsError(std::string("JPEG-LS encode failed: ") + e.what());
  }
}

cv::Mat jpegls_decode(std::span<const std::uint8_t> data, int width, int height, int bits) {
  check_bits(bits);
  if (data.empty()) throw JpegLsError("JPEG-LS decode: empty input");
  // A complete stream starts with SOI (FF D8) and ends with EOI (FF D9). Checked up front because
  // CharLS 2.4 can spend seconds on a stream that ends inside the scan data (it keeps decoding
  // past the end of the buffer before it reports the error); with a marker at the end it stops at once.
  if (data.size() < 4 || data[0] != 0xFF || data[1] != 0xD8 || data[data.size() - 2] != 0xFF ||
      data[data.size() - 1] != 0xD9)
    throw JpegLsError("JPEG-LS decode: not a complete image (missing start or end-of-image marker)");
  try {
    charls::jpegls_decoder decoder;
    decoder.source(data.data(), data.size());
    decoder.read_header();
    // Never trust the stream's own header: it must be exactly the rectangle we expect, lossless, and
    // without a colour transform, before CharLS writes a single pixel.
    const charls::frame_info& info = decoder.frame_info();
    if (static_cast<int>(info.width) != width || static_cast<int>(info.height) != height)
      throw JpegLsError("JPEG-LS decode: image is " + std::to_string(info.width) + "x" + std::to_string(info.height) +
                        ", expected " + std::to_string(width) + "x" + std::to_string(height));
    if (info.component_count != 3 || info.bits_per_sample != bits)
      throw JpegLsError("JPEG-LS decode: expected 3 components of " + std::to_string(bits) + " bits");
    if (decoder.near_lossless() != 0) throw JpegLsError("JPEG-LS decode: stream is near-lossless, not lossless");
    if (decoder.interleave_mode() != charls::interleave_mode::sample)
      throw JpegLsError("JPEG-LS decode: expected sample-interleaved RGB");  // else CharLS writes planes
    if (decoder.color_transformation() != charls::color_transformation::none)
      throw JpegLsError("JPEG-LS decode: unexpected colour transformation");

    const int type = bits == 8 ? CV_8UC3 : CV_16UC3;
    cv::Mat decoded(height, width, type);
    const std::size_t bytes = decoded.total() * decoded.elemSize();
    if (decoder.destination_size() != bytes) throw JpegLsError("JPEG-LS decode: unexpected decoded size");
    decoder.decode(decoded.data, bytes);
    if (bits == 8) {
      cv::Mat wide;
      decoded.convertTo(wide, CV_16UC3);
      return wide;
    }
    // 10-bit samples arrive in 16-bit words; CharLS masks them to 10 bits, but check rather than assume.
    if (highest_code(decoded) >= 1024) throw JpegLsError("JPEG-LS decode: sample exceeds 10 bits");
    return decoded;
  } catch (const JpegLsError&) {
    throw;
  } catch (const std::exception& e) {
    throw JpegLsError(std::string("JPEG-LS decode failed: ") + e.what());
  }
}

void LosslessTally::add(const LinkFrame& view) {
  coded_bits += static_cast<std::uint64_t>(jpegls_encode(view.codes, view.meta.bits).size()) * 8u;
  sent_pixels += view.codes.total();
  displayed_pixels += static_cast<std::uint64_t>(view.meta.full_width) * static_cast<std::uint64_t>(view.meta.full_height);
}

}  // namespace trm::link
