#include "trm/link.hpp"
#include "trm/jpegls.hpp"

#include "bit_packing.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace trm::link {

namespace {

// The rectangles a view is cut into, in transmission order (docs/link.md, "Packetisation").
std::vector<cv::Rect> plan_rectangles(int width, int height, int bits, const PacketizerConfig& config) {
  std::vector<cv::Rect> rects;
  if (config.coding == PayloadCoding::JpegLs) {
    const int lines = std::min(config.max_lines_per_packet, height);
    for (int y = 0; y < height; y += lines) rects.emplace_back(0, y, width, std::min(lines, height - y));
    return rects;
  }
  const std::uint64_t payload_bit_budget = static_cast<std::uint64_t>(config.max_payload_bytes) * 8u;
  const std::uint64_t line_bits = static_cast<std::uint64_t>(width) * 3u * static_cast<std::uint64_t>(bits);
  const std::uint64_t whole_lines = payload_bit_budget / line_bits;  // ceil(k*line_bits/8) <= budget for this k
  if (whole_lines >= 1) {
    const int lines = static_cast<int>(std::min<std::uint64_t>(whole_lines, static_cast<std::uint64_t>(config.max_lines_per_packet)));
    for (int y = 0; y < height; y += lines) rects.emplace_back(0, y, width, std::min(lines, height - y));
    return rects;
  }
  // A line does not fit: cut each line into column slices of as many pixels as fit.
  const int columns = static_cast<int>(payload_bit_budget / (3u * static_cast<std::uint64_t>(bits)));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; x += columns) rects.emplace_back(x, y, std::min(columns, width - x), 1);
  return rects;
}

void validate_meta(const FrameMeta& m) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("link transmitter: " + what); };
  if (m.eye < 0 || m.eye >= kMaxStreams) bad("eye must be 0 or 1, got " + std::to_string(m.eye));
  if (m.index < 0) bad("frame index must be >= 0, got " + std::to_string(m.index));
  if (m.width < 1 || m.height < 1 || m.width > kMaxDimension || m.height > kMaxDimension)
    bad("view size " + std::to_string(m.width) + "x" + std::to_string(m.height) + " outside 1..65535");
  if (m.full_width < m.width || m.full_height < m.height || m.full_width > kMaxDimension ||
      m.full_height > kMaxDimension)
    bad("full size " + std::to_string(m.full_width) + "x" + std::to_string(m.full_height) +
        " must be at least the view size and at most 65535");
  if (m.parity == Parity::Full && (m.width != m.full_width || m.height != m.full_height))
    bad("a full frame must be sent at its full size");
  if (m.bits != 8 && m.bits != 10) bad("link bits must be 8 or 10, got " + std::to_string(m.bits));
}

}  // namespace

void PacketizerConfig::validate() const {
  if (max_lines_per_packet < 1)
    throw std::invalid_argument("lines per packet must be >= 1, got " + std::to_string(max_lines_per_packet));
  // 4 bytes hold one 10-bit RGB pixel (30 bits): the smallest useful raw payload.
  if (coding == PayloadCoding::Raw && max_payload_bytes < 4)
    throw std::invalid_argument("maximum packet payload must be >= 4 bytes (one 10-bit RGB pixel), got " +
                                std::to_string(max_payload_bytes));
}

ViewBits& ViewBits::operator+=(const ViewBits& o) {
  pixel_bits += o.pixel_bits;
  payload_bits += o.payload_bits;
  overhead_bits += o.overhead_bits;
  packets += o.packets;
  return *this;
}

ViewBits predict_raw_view_bits(const FrameMeta& meta, const PacketizerConfig& config) {
  config.validate();
  if (config.coding != PayloadCoding::Raw)
    throw std::invalid_argument("link bits can only be predicted for raw payloads (JPEG-LS size depends on content)");
  validate_meta(meta);
  ViewBits bits;
  for (const cv::Rect& r : plan_rectangles(meta.width, meta.height, meta.bits, config)) {
    const std::uint64_t pixel_bits =
        static_cast<std::uint64_t>(r.area()) * 3u * static_cast<std::uint64_t>(meta.bits);
    const std::uint64_t payload_bytes = raw_payload_bytes(r.width, r.height, meta.bits);
    bits.pixel_bits += pixel_bits;
    bits.payload_bits += pixel_bits;
    // Padding to a whole byte is overhead, so that the payload is exactly the image.
    bits.overhead_bits += payload_bytes * 8u - pixel_bits + kPacketOverheadBytes * 8u;
    ++bits.packets;
  }
  return bits;
}

Transmitter::Transmitter(PacketizerConfig config) : config_(config) { config_.validate(); }

SentView Transmitter::send(const LinkFrame& view) {
  const FrameMeta& m = view.meta;
  validate_meta(m);
  if (view.codes.type() != CV_16UC3 || view.codes.cols != m.width || view.codes.rows != m.height)
    throw std::invalid_argument("link transmitter: codes must be CV_16UC3 of " + std::to_string(m.width) + "x" +
                                std::to_string(m.height) + " (the size in the frame's metadata)");
  const int max_code = highest_code(view.codes);
  if (max_code >= (1 << m.bits))
    throw std::invalid_argument("link transmitter: code " + std::to_string(max_code) +
                                " does not fit " + std::to_string(m.bits) + " bits");

  SentView sent;
  sent.meta = m;
  PacketHeader h;
  h.stream = m.eye;
  h.parity = m.parity;
  h.frame_index = m.index;
  h.width = m.width;
  h.height = m.height;
  h.full_width = m.full_width;
  h.full_height = m.full_height;
  h.bits = m.bits;
  h.transfer = m.transfer;
  h.coding = config_.coding;

  std::vector<std::uint8_t> payload;
  for (const cv::Rect& r : plan_rectangles(m.width, m.height, m.bits, config_)) {
    h.first_line = r.y;
    h.line_count = r.height;
    h.first_column = r.x;
    h.column_count = r.width;
    h.sequence = next_sequence_[m.eye]++;
    const std::uint64_t pixel_bits = static_cast<std::uint64_t>(r.area()) * 3u * static_cast<std::uint64_t>(m.bits);
    payload.clear();
    if (config_.coding == PayloadCoding::Raw) {
      detail::pack_codes(view.codes, r, m.bits, payload);
      sent.bits.payload_bits += pixel_bits;
      sent.bits.overhead_bits += payload.size() * 8u - pixel_bits;  // byte padding
    } else {
      payload = jpegls_encode(view.codes(r), m.bits);
      sent.bits.payload_bits += payload.size() * 8u;
    }
    sent.bits.pixel_bits += pixel_bits;
    sent.bits.overhead_bits += kPacketOverheadBytes * 8u;
    ++sent.bits.packets;
    sent.packets.push_back(build_packet(h, payload));
  }
  return sent;
}

}  // namespace trm::link
