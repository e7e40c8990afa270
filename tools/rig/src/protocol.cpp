#include "rig/protocol.hpp"


#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace trm::rig {
namespace {

void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put_i64(std::uint8_t* p, std::int64_t v) {
  const auto u = static_cast<std::uint64_t>(v);
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(u >> (8 * i));
}
std::uint16_t get_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
std::uint32_t get_u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
std::int64_t get_i64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return static_cast<std::int64_t>(v);
}

[[noreturn]] void malformed(const std::string& what) { throw std::runtime_error("rig protocol: " + what); }

// What a rig checks in a FRAME_START beyond its CRC and version, so that the frame it reassembles is a
// valid RigFrame: RGB order, 1..16 bits in the bytes per sample they take, a size of at least 1x1 whose
// width x height x 3 x bytes per sample is the payload length, a step of at least 1, view and region
// fields that fit an int.
void check_frame_start(const FrameStart& s) {
  if (s.channel_order != ChannelOrder::Rgb)
    malformed("FRAME_START channel order " + std::to_string(static_cast<int>(s.channel_order)) + " is not RGB (0)");
  if (s.bits < 1 || s.bits > 16) malformed("FRAME_START bits per channel " + std::to_string(s.bits) + " outside 1..16");
  if (s.bytes_per_sample != (s.bits <= 8 ? 1 : 2))
    malformed("FRAME_START bytes per sample " + std::to_string(s.bytes_per_sample) + " does not match " +
              std::to_string(s.bits) + " bits");
  if (s.width < 1 || s.height < 1 || s.width > std::numeric_limits<int>::max() || s.height > std::numeric_limits<int>::max())
    malformed("FRAME_START size " + std::to_string(s.width) + "x" + std::to_string(s.height) + " out of range");
  const std::uint64_t pixels = static_cast<std::uint64_t>(s.width) * s.height;  // < 2^62
  if (pixels > s.payload_length || pixels * 3u * s.bytes_per_sample != s.payload_length)
    malformed("FRAME_START payload length " + std::to_string(s.payload_length) + " is not width x height x 3 x " +
              std::to_string(s.bytes_per_sample));
  if (s.step < 1) malformed("FRAME_START step 0");
  for (std::uint32_t v : {s.view_width, s.view_height, s.region_x, s.region_y})
    if (v > static_cast<std::uint32_t>(std::numeric_limits<int>::max())) malformed("FRAME_START view or region field out of range");
}

std::uint32_t checked_u32(std::size_t v, const char* what) {
  if (v > std::numeric_limits<std::uint32_t>::max()) throw std::invalid_argument(std::string(what) + " too large");
  return static_cast<std::uint32_t>(v);
}

}  // namespace

std::size_t RigFrameHeader::payload_size() const {
  return static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3u *
         static_cast<std::size_t>(bytes_per_sample());
}

namespace {

// Everything validate() checks but the codes themselves.
void check_layout(const RigFrameHeader& f, std::size_t sample_count) {
  if (f.width <= 0 || f.height <= 0) throw std::invalid_argument("rig frame: width and height must be positive");
  if (f.bits < 1 || f.bits > 16) throw std::invalid_argument("rig frame: bits per channel must be 1..16");
  if (f.eye < 0 || f.eye > 255) throw std::invalid_argument("rig frame: eye must be 0..255");
  if (f.step < 1 || f.step > 0xFFFF) throw std::invalid_argument("rig frame: step must be 1..65535");
  if (sample_count != static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height) * 3u)
    throw std::invalid_argument("rig frame: sample count is not width * height * 3");
}

// max_code is 2^bits - 1, so a code exceeds it exactly when it has a bit above it: one OR over the frame (a loop
// without an early exit, which the compiler vectorises) instead of a comparison and branch per sample.
void check_codes(std::uint16_t any_bits, int bits) {
  const auto max_code = static_cast<std::uint16_t>((1u << bits) - 1u);
  if ((any_bits & ~max_code) != 0) throw std::invalid_argument("rig frame: a drive code exceeds its bit depth");
}

}  // namespace

void RigFrame::validate() const {
  check_layout(*this, samples.size());
  std::uint16_t any_bits = 0;
  for (const std::uint16_t s : samples) any_bits |= s;
  check_codes(any_bits, bits);
}

RigFrame crop_and_decimate(const RigFrame& view, const Region& region, int step) {
  if (step < 1) throw std::invalid_argument("downscale step must be >= 1");
  // Compared by subtraction: x + width can exceed INT_MAX.
  if (region.width <= 0 || region.height <= 0 || region.x < 0 || region.y < 0 || region.width > view.width ||
      region.height > view.height || region.x > view.width - region.width || region.y > view.height - region.height)
    throw std::invalid_argument("--roi " + std::to_string(region.x) + "," + std::to_string(region.y) + "," +
                                std::to_string(region.width) + "," + std::to_string(region.height) +
                                " does not lie inside the " + std::to_string(view.width) + "x" +
                                std::to_string(view.height) + " view");
  RigFrame out;
  out.index = view.index;
  out.eye = view.eye;
  out.bits = view.bits;
  out.view_width = view.view_width ? view.view_width : view.width;
  out.view_height = view.view_height ? view.view_height : view.height;
  out.region_x = view.region_x + region.x * view.step;
  out.region_y = view.region_y + region.y * view.step;
  out.step = view.step * step;
  out.width = (region.width + step - 1) / step;
  out.height = (region.height + step - 1) / step;
  out.samples.reserve(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height) * 3u);
  for (int y = region.y; y < region.y + region.height; y += step) {
    const std::uint16_t* row = view.samples.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(view.width) * 3u;
    for (int x = region.x; x < region.x + region.width; x += step)
      out.samples.insert(out.samples.end(), row + static_cast<std::size_t>(x) * 3u, row + static_cast<std::size_t>(x) * 3u + 3u);
  }
  return out;
}

const char* describe_rig_error_code(std::uint8_t code) {
  switch (code) {
    case 1: return "payload CRC mismatch";
    case 2: return "unsupported frame format (size, bits or channel order)";
    case 3: return "rig out of buffer memory";
    case 4: return "protocol violation (unexpected packet or sequence)";
    default: return "rig-specific error";
  }
}

std::vector<std::uint8_t> pack_samples(const RigFrame& frame) { return pack_samples(frame, frame.samples); }

std::vector<std::uint8_t> pack_samples(const RigFrameHeader& header, std::span<const std::uint16_t> samples) {
  std::vector<std::uint8_t> out;
  pack_samples(header, samples, out);
  return out;
}

void pack_samples(const RigFrameHeader& header, std::span<const std::uint16_t> samples, std::vector<std::uint8_t>& out) {
  check_layout(header, samples.size());
  out.resize(header.payload_size());
  // Through local restrict pointers: a uint8_t store may alias anything, which otherwise keeps these loops scalar.
  // The codes are checked against the bit depth in the same pass (validate()'s check without a pass of its own).
  const std::uint16_t* __restrict in = samples.data();
  std::uint8_t* __restrict bytes = out.data();
  const std::size_t n = samples.size();
  std::uint16_t any_bits = 0;
  if (header.bytes_per_sample() == 1) {
    for (std::size_t i = 0; i < n; ++i) {
      any_bits |= in[i];
      bytes[i] = static_cast<std::uint8_t>(in[i]);
    }
  } else {
    for (std::size_t i = 0; i < n; ++i) {  // little endian, as put_u16
      any_bits |= in[i];
      bytes[2 * i] = static_cast<std::uint8_t>(in[i]);
      bytes[2 * i + 1] = static_cast<std::uint8_t>(in[i] >> 8);
    }
  }
  check_codes(any_bits, header.bits);
}

std::vector<std::uint8_t> encode_frame_start(const FrameStart& s) {
  std::vector<std::uint8_t> p(kFrameStartSize, 0);
  p[0] = static_cast<std::uint8_t>(PacketType::FrameStart);
  std::memcpy(&p[1], kStartMagic.data(), kStartMagic.size());
  p[4] = s.version;
  p[5] = static_cast<std::uint8_t>(s.channel_order);
  p[6] = s.bits;
  p[7] = s.bytes_per_sample;
  put_i64(&p[8], s.frame_index);
  p[16] = s.eye;
  p[17] = s.flags;
  put_u16(&p[18], s.chunk_data_size);
  put_u32(&p[20], s.width);
  put_u32(&p[24], s.height);
  put_u32(&p[28], s.view_width);
  put_u32(&p[32], s.view_height);
  put_u32(&p[36], s.region_x);
  put_u32(&p[40], s.region_y);
  put_u16(&p[44], s.step);
  // 46..47 reserved, zero.
  put_u32(&p[48], s.payload_length);
  put_u32(&p[52], s.chunk_count);
  put_u32(&p[56], s.payload_crc);
  put_u32(&p[60], crc32_ieee(std::span(p).first(60)));
  return p;
}

namespace {

void encode_chunk_into(const ChunkHeader& h, std::span<const std::uint8_t> data, std::vector<std::uint8_t>& p) {
  if (data.size() != h.length) throw std::invalid_argument("chunk length does not match its data");
  p.resize(kChunkHeaderSize + data.size());
  p[0] = static_cast<std::uint8_t>(PacketType::Chunk);
  p[1] = h.last ? kChunkFlagLast : 0;
  put_u16(&p[2], h.length);
  put_u32(&p[4], h.sequence);
  if (!data.empty()) std::memcpy(&p[kChunkHeaderSize], data.data(), data.size());
}

}  // namespace

std::vector<std::uint8_t> encode_chunk(const ChunkHeader& h, std::span<const std::uint8_t> data) {
  std::vector<std::uint8_t> p;
  encode_chunk_into(h, data, p);
  return p;
}

std::vector<std::uint8_t> encode_frame_end(const FrameEnd& e) {
  std::vector<std::uint8_t> p(kFrameEndSize, 0);
  p[0] = static_cast<std::uint8_t>(PacketType::FrameEnd);
  put_u32(&p[4], e.chunk_count);
  put_i64(&p[8], e.frame_index);
  put_u32(&p[16], e.payload_crc);
  put_u32(&p[20], crc32_ieee(std::span(p).first(20)));
  return p;
}

std::vector<std::uint8_t> encode_answer(const Answer& a) {
  std::vector<std::uint8_t> p(kAnswerSize, 0);
  p[0] = static_cast<std::uint8_t>(a.kind);
  p[1] = a.error_code;
  put_u32(&p[4], a.sequence);
  put_i64(&p[8], a.frame_index);
  return p;
}

FrameStart decode_frame_start(std::span<const std::uint8_t> p) {
  if (p.size() < kFrameStartSize) malformed("FRAME_START shorter than 64 bytes");
  if (p[0] != static_cast<std::uint8_t>(PacketType::FrameStart)) malformed("not a FRAME_START packet");
  if (!std::equal(kStartMagic.begin(), kStartMagic.end(), p.begin() + 1)) malformed("bad FRAME_START magic");
  if (get_u32(&p[60]) != crc32_ieee(p.first(60))) malformed("FRAME_START header CRC mismatch");
  FrameStart s;
  s.version = p[4];
  if (s.version != kProtocolVersion) malformed("unsupported protocol version " + std::to_string(s.version));
  s.channel_order = static_cast<ChannelOrder>(p[5]);
  s.bits = p[6];
  s.bytes_per_sample = p[7];
  s.frame_index = get_i64(&p[8]);
  s.eye = p[16];
  s.flags = p[17];
  s.chunk_data_size = get_u16(&p[18]);
  s.width = get_u32(&p[20]);
  s.height = get_u32(&p[24]);
  s.view_width = get_u32(&p[28]);
  s.view_height = get_u32(&p[32]);
  s.region_x = get_u32(&p[36]);
  s.region_y = get_u32(&p[40]);
  s.step = get_u16(&p[44]);
  s.payload_length = get_u32(&p[48]);
  s.chunk_count = get_u32(&p[52]);
  s.payload_crc = get_u32(&p[56]);
  return s;
}

ChunkHeader decode_chunk_header(std::span<const std::uint8_t> p) {
  if (p.size() < kChunkHeaderSize || p[0] != static_cast<std::uint8_t>(PacketType::Chunk)) malformed("not a CHUNK packet");
  ChunkHeader h;
  h.last = (p[1] & kChunkFlagLast) != 0;
  h.length = get_u16(&p[2]);
  h.sequence = get_u32(&p[4]);
  if (p.size() < kChunkHeaderSize + h.length) malformed("CHUNK shorter than its length field");
  return h;
}

FrameEnd decode_frame_end(std::span<const std::uint8_t> p) {
  if (p.size() < kFrameEndSize || p[0] != static_cast<std::uint8_t>(PacketType::FrameEnd)) malformed("not a FRAME_END packet");
  if (get_u32(&p[20]) != crc32_ieee(p.first(20))) malformed("FRAME_END CRC mismatch");
  return FrameEnd{get_u32(&p[4]), get_i64(&p[8]), get_u32(&p[16])};
}

std::optional<Answer> decode_answer(std::span<const std::uint8_t> p) {
  if (p.size() < kAnswerSize) return std::nullopt;
  if (p[0] != static_cast<std::uint8_t>(AnswerKind::Ready) && p[0] != static_cast<std::uint8_t>(AnswerKind::Resend) &&
      p[0] != static_cast<std::uint8_t>(AnswerKind::Error))
    return std::nullopt;
  return Answer{static_cast<AnswerKind>(p[0]), p[1], get_u32(&p[4]), get_i64(&p[8])};
}

std::size_t packet_size_in_stream(std::span<const std::uint8_t> b) {
  if (b.empty()) return 0;
  switch (static_cast<PacketType>(b[0])) {
    case PacketType::FrameStart: return kFrameStartSize;
    case PacketType::FrameEnd: return kFrameEndSize;
    case PacketType::Chunk: return b.size() < kChunkHeaderSize ? 0 : kChunkHeaderSize + get_u16(&b[2]);
    default: malformed("unknown packet type " + std::to_string(b[0]) + " in stream");
  }
}

std::vector<std::vector<std::uint8_t>> split_stream(std::span<const std::uint8_t> stream) {
  std::vector<std::vector<std::uint8_t>> packets;
  std::size_t at = 0;
  while (at < stream.size()) {
    const std::size_t n = packet_size_in_stream(stream.subspan(at));
    if (n == 0 || at + n > stream.size()) malformed("stream ends inside a packet");
    packets.emplace_back(stream.begin() + static_cast<std::ptrdiff_t>(at), stream.begin() + static_cast<std::ptrdiff_t>(at + n));
    at += n;
  }
  return packets;
}

std::vector<std::uint8_t> EncodedFrame::chunk_packet(std::uint32_t sequence) const {
  std::vector<std::uint8_t> out;
  chunk_packet(sequence, out);
  return out;
}

void EncodedFrame::chunk_packet(std::uint32_t sequence, std::vector<std::uint8_t>& out) const {
  const std::size_t begin = static_cast<std::size_t>(sequence) * chunk_data_size;
  const std::size_t end = std::min(payload.size(), begin + chunk_data_size);
  ChunkHeader h;
  h.sequence = sequence;
  h.last = sequence + 1 == start.chunk_count;
  h.length = static_cast<std::uint16_t>(end - begin);
  encode_chunk_into(h, std::span(payload).subspan(begin, end - begin), out);
}

std::size_t EncodedFrame::wire_size() const {
  return start_packet.size() + end_packet.size() + payload.size() + kChunkHeaderSize * start.chunk_count;
}

EncodedFrame encode_frame(const RigFrame& frame, std::size_t max_packet_size, bool answer_expected) {
  return encode_frame(frame, frame.samples, max_packet_size, answer_expected);
}

EncodedFrame encode_frame(const RigFrameHeader& frame, std::span<const std::uint16_t> samples, std::size_t max_packet_size,
                          bool answer_expected) {
  EncodedFrame e;
  encode_frame(frame, samples, max_packet_size, answer_expected, e);
  return e;
}

void encode_frame(const RigFrameHeader& frame, std::span<const std::uint16_t> samples, std::size_t max_packet_size,
                  bool answer_expected, EncodedFrame& e) {
  check_layout(frame, samples.size());  // the codes are checked as they are packed
  if (max_packet_size < kMinPacketSize)
    throw std::invalid_argument("transport packets of " + std::to_string(max_packet_size) +
                                " bytes cannot carry a 64-byte FRAME_START");
  e.chunk_data_size = std::min(max_packet_size - kChunkHeaderSize, kMaxChunkData);
  e.start = FrameStart{};
  pack_samples(frame, samples, e.payload);
  FrameStart& s = e.start;
  s.bits = static_cast<std::uint8_t>(frame.bits);
  s.bytes_per_sample = static_cast<std::uint8_t>(frame.bytes_per_sample());
  s.frame_index = frame.index;
  s.eye = static_cast<std::uint8_t>(frame.eye);
  s.flags = answer_expected ? kFlagAnswerExpected : 0;
  s.chunk_data_size = static_cast<std::uint16_t>(e.chunk_data_size);
  s.width = checked_u32(static_cast<std::size_t>(frame.width), "width");
  s.height = checked_u32(static_cast<std::size_t>(frame.height), "height");
  s.view_width = checked_u32(static_cast<std::size_t>(frame.view_width ? frame.view_width : frame.width), "view width");
  s.view_height = checked_u32(static_cast<std::size_t>(frame.view_height ? frame.view_height : frame.height), "view height");
  s.region_x = checked_u32(static_cast<std::size_t>(frame.region_x), "region x");
  s.region_y = checked_u32(static_cast<std::size_t>(frame.region_y), "region y");
  s.step = static_cast<std::uint16_t>(frame.step);
  s.payload_length = checked_u32(e.payload.size(), "frame payload");
  s.chunk_count = checked_u32((e.payload.size() + e.chunk_data_size - 1) / e.chunk_data_size, "chunk count");
  s.payload_crc = crc32_ieee(e.payload);
  e.start_packet = encode_frame_start(s);
  e.end_packet = encode_frame_end(FrameEnd{s.chunk_count, s.frame_index, s.payload_crc});
}

void StreamReceiver::accept_packet(std::span<const std::uint8_t> packet) {
  if (packet.empty()) malformed("empty packet");
  switch (static_cast<PacketType>(packet[0])) {
    case PacketType::FrameStart: {
      if (open_) malformed("FRAME_START while frame " + std::to_string(open_->frame_index) + " is open");
      const FrameStart start = decode_frame_start(packet);
      check_frame_start(start);
      open_ = start;
      payload_.clear();
      // Grown as chunks arrive beyond this: a corrupt length cannot make the receiver allocate gigabytes.
      payload_.reserve(std::min<std::size_t>(open_->payload_length, std::size_t{1} << 24));
      next_sequence_ = 0;
      return;
    }
    case PacketType::Chunk: {
      if (!open_) malformed("CHUNK outside a frame");
      const ChunkHeader h = decode_chunk_header(packet);
      sequences_.push_back(h.sequence);
      if (h.sequence > next_sequence_) malformed("chunk sequence gap: expected " + std::to_string(next_sequence_) +
                                                 ", got " + std::to_string(h.sequence));
      if (h.sequence < next_sequence_)  // a resend: rewind to where it starts
        payload_.resize(static_cast<std::size_t>(h.sequence) * open_->chunk_data_size);
      const bool should_be_last = h.sequence + 1 == open_->chunk_count;
      if (h.last != should_be_last) malformed("last-chunk flag wrong on chunk " + std::to_string(h.sequence));
      if (!h.last && h.length != open_->chunk_data_size) malformed("short chunk before the last one");
      payload_.insert(payload_.end(), packet.begin() + kChunkHeaderSize, packet.begin() + kChunkHeaderSize + h.length);
      next_sequence_ = h.sequence + 1;
      return;
    }
    case PacketType::FrameEnd: {
      if (!open_) malformed("FRAME_END outside a frame");
      const FrameEnd e = decode_frame_end(packet);
      if (e.frame_index != open_->frame_index || e.chunk_count != open_->chunk_count || next_sequence_ != e.chunk_count)
        malformed("FRAME_END does not match the open frame");
      if (payload_.size() != open_->payload_length) malformed("payload length mismatch");
      if (crc32_ieee(payload_) != open_->payload_crc || e.payload_crc != open_->payload_crc) malformed("payload CRC mismatch");
      RigFrame f;
      f.index = open_->frame_index;
      f.eye = open_->eye;
      f.width = static_cast<int>(open_->width);
      f.height = static_cast<int>(open_->height);
      f.bits = open_->bits;
      f.view_width = static_cast<int>(open_->view_width);
      f.view_height = static_cast<int>(open_->view_height);
      f.region_x = static_cast<int>(open_->region_x);
      f.region_y = static_cast<int>(open_->region_y);
      f.step = open_->step;
      f.samples.resize(payload_.size() / open_->bytes_per_sample);
      const auto max_code = static_cast<std::uint16_t>((1u << open_->bits) - 1u);
      for (std::size_t i = 0; i < f.samples.size(); ++i) {
        f.samples[i] = open_->bytes_per_sample == 1 ? payload_[i] : get_u16(&payload_[2 * i]);
        if (f.samples[i] > max_code) malformed("a drive code exceeds " + std::to_string(open_->bits) + " bits");
      }
      frames_.push_back(std::move(f));
      open_.reset();
      return;
    }
    default: malformed("unexpected packet type " + std::to_string(packet[0]));
  }
}

}  // namespace trm::rig
