// Link transmitter and receiver: LinkFrame views in, packets on the wire, reassembled views out.
//
// Typical use for one run (the simulator's link frame t carries one view in mono, two in stereo):
//
//   link::Transmitter tx(packetizer);              link::Receiver rx;
//   for each link frame t:
//     for each view:  auto sent = tx.send(view);   // packets + bit accounting
//                     for (auto& p : sent.packets) if (faults.apply(p)) rx.push(p);
//     rx.flush();                                  // link frame over: hand out what arrived
//     for (auto& f : rx.take_frames()) decoder(f); // f.line_intact says which lines to conceal
#pragma once

#include "trm/packet.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace trm::link {

struct PacketizerConfig {
  // Whole lines per packet, at most. 1 = one line per packet, so a lost packet costs one line.
  // With JPEG-LS coding a packet is an independently coded slice of this many lines; a value at
  // least the view height codes the whole view as one image ("per frame").
  int max_lines_per_packet = 1;
  // Raw coding only: a packet's payload never exceeds this; lines per packet are reduced to fit,
  // and a single line that does not fit is cut into column slices. Must hold one pixel (4 bytes).
  std::size_t max_payload_bytes = 8192;
  PayloadCoding coding = PayloadCoding::Raw;

  void validate() const;  // throws std::invalid_argument
};

// Bits of one view (or the sum of several), split as the bandwidth report needs them.
struct ViewBits {
  std::uint64_t pixel_bits = 0;     // W*H*3*bits of the codes carried: the raw image, whatever the coding
  std::uint64_t payload_bits = 0;   // raw: == pixel_bits; JPEG-LS: coded bytes * 8
  std::uint64_t overhead_bits = 0;  // headers, CRCs and, for raw payloads, the padding to a whole byte
  std::uint64_t packets = 0;
  std::uint64_t wire_bits() const { return payload_bits + overhead_bits; }
  ViewBits& operator+=(const ViewBits& other);
};
// For raw coding payload_bits == pixel_bits exactly: a packet's padding bits are counted as overhead,
// so the payload of a frame pair is exactly (W*H + w*h) / (2*W*H) of full rate (DESIGN §6).

struct SentView {
  FrameMeta meta;
  std::vector<std::vector<std::uint8_t>> packets;  // in transmission order
  ViewBits bits;
};

class Transmitter {
 public:
  explicit Transmitter(PacketizerConfig config = {});
  const PacketizerConfig& config() const { return config_; }

  // Packetises one view. Validates the frame first (CV_16UC3 of meta.width x meta.height, sizes within
  // the 16-bit header fields, bits 8/10, every code < 2^bits, stream 0/1) and throws
  // std::invalid_argument naming the problem.
  SentView send(const LinkFrame& view);

 private:
  PacketizerConfig config_;
  std::uint32_t next_sequence_[kMaxStreams] = {0, 0};
};

// The bits a raw-coded view of this geometry costs, without building packets (for the full-rate
// comparison series and for link sizing). Throws std::invalid_argument when coding is not raw.
ViewBits predict_raw_view_bits(const FrameMeta& meta, const PacketizerConfig& config);

// One view as reassembled. Lines that did not arrive intact are zero in `codes` and 0 in line_intact.
struct ReceivedFrame {
  FrameMeta meta;                       // from the packet headers (validated, consistent across the view)
  cv::Mat codes;                        // CV_16UC3, meta.height x meta.width
  std::vector<std::uint8_t> line_intact;  // one entry per line: 1 = every pixel arrived in a CRC-clean packet
  int intact_lines() const;
  bool complete() const { return intact_lines() == meta.height; }
};

struct ReceiverCounters {
  std::uint64_t packets_received = 0;   // push() calls
  std::uint64_t packets_accepted = 0;
  std::uint64_t crc_failures = 0;       // damaged packets (PacketError::CrcMismatch)
  std::uint64_t malformed = 0;          // CRC-clean but invalid (any other PacketError), or an undecodable payload
  std::uint64_t inconsistent = 0;       // valid, but disagreeing with the view's earlier packets
  std::uint64_t duplicates = 0;         // covering pixels already received
  std::uint64_t stale = 0;              // for a frame already handed out
  std::uint64_t sequence_gaps = 0;      // packets missing according to the per-stream sequence numbers
  std::uint64_t frames_out = 0;
  std::uint64_t frames_complete = 0;
  std::uint64_t frames_partial = 0;     // handed out with at least one line not intact
  std::uint64_t lines_lost = 0;         // non-intact lines over all frames handed out
  std::uint64_t frame_index_gaps = 0;   // frame indices skipped entirely (no packet of theirs arrived)
};

enum class PushResult : std::uint8_t { Accepted, Damaged, Malformed, Inconsistent, Duplicate, Stale };
const char* to_string(PushResult result);

// Reassembles views from packets. Never trusts a packet: everything is validated (parse_packet), and a
// view's geometry is fixed by its first accepted packet; later packets must agree. Never throws on bad
// input; bad packets are counted and dropped.
//
// Frames are handed out when the link moves on: when a packet of a later frame index arrives (every
// view of earlier frames is then finished), or on flush(). They come out in (frame index, stream) order.
class Receiver {
 public:
  explicit Receiver(ReceiverLimits limits = {});

  PushResult push(std::span<const std::uint8_t> packet);
  void flush();                              // end of a link frame or of the stream
  std::vector<ReceivedFrame> take_frames();  // frames handed out since the last call

  const ReceiverCounters& counters() const { return counters_; }
  PacketError last_packet_error() const { return last_error_; }

 private:
  struct Assembly {
    bool active = false;
    FrameMeta meta;
    cv::Mat codes;
    cv::Mat coverage;  // CV_8U, 1 where a pixel arrived
  };
  void hand_out_all();

  ReceiverLimits limits_;
  ReceiverCounters counters_;
  PacketError last_error_ = PacketError::None;
  Assembly assembly_[kMaxStreams];
  bool have_index_ = false;
  std::int64_t current_index_ = 0;          // frame index being assembled
  bool have_handed_out_ = false;
  std::int64_t handed_out_through_ = 0;     // packets of this index or earlier are stale
  bool have_sequence_[kMaxStreams] = {false, false};
  std::uint32_t expected_sequence_[kMaxStreams] = {0, 0};
  std::vector<ReceivedFrame> ready_;
  cv::Mat scratch_;                          // decoded slice
};

}  // namespace trm::link
