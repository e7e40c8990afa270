// libFuzzer target for the rig protocol's flow-control answers: RigFeeder streams small frames with flow
// control on into a fake transport whose rig "answers" (READY / RESEND / ERROR or anything else) come from
// the fuzz input. A shadow rig decodes every packet the feeder sends and checks the protocol: frames go
// out whole and in order, a resend restarts at exactly the chunk the answer named, the reassembled
// payload is the frame's, a frame counts as sent only after a READY for it, and every failure is a
// RigError (never another exception, a crash or undefined behaviour).
//
// Input: 6 configuration bytes (width, height, bits, transport packet size, resends allowed, frames),
// then answer records [flags][length][length bytes]. Flags help mutations reach the logic behind the
// frame-index match: bit 0 writes the current frame's index into bytes 8..15, bit 1 reduces the resend
// sequence (bytes 4..7) modulo chunk count + 1 (so it is valid or one past the end), bit 2 makes byte 0 a
// valid answer kind. When the records run out the fake transport reports a timeout.
#include "fuzz_support.hpp"
#include "rig/feeder.hpp"
#include "rig/protocol.hpp"
#include "rig/transport.hpp"

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

using trm::fuzz::check;
using namespace trm::rig;

namespace {

struct Input {
  const std::uint8_t* data;
  std::size_t size;
  std::size_t at = 0;
  bool empty() const { return at >= size; }
  std::uint8_t byte() { return at < size ? data[at++] : 0; }
};

// What the feeder sent, as a rig sees it, and what the rig last answered.
class ShadowRig final : public RigTransport {
 public:
  ShadowRig(Input& input, std::size_t packet_size) : input_(input), packet_size_(packet_size) {}

  const RigFrame* frame = nullptr;  // the frame being fed
  std::optional<Answer> last_answer;
  int resends_this_frame = 0;
  std::int64_t resends_total = 0;
  bool frame_complete = false;  // FRAME_END sent with a payload equal to the frame's

  std::string description() const override { return "fuzz shadow rig"; }
  std::size_t max_packet_size() const override { return packet_size_; }
  bool can_receive() const override { return true; }
  TransportRate nominal_rate() const override { return {}; }

  void send(std::span<const std::uint8_t> packet) override {
    check(!packet.empty() && packet.size() <= packet_size_, "packet empty or larger than the transport's");
    switch (static_cast<PacketType>(packet[0])) {
      case PacketType::FrameStart: {
        check(state_ == State::Idle, "FRAME_START while a frame is under way");
        start_ = decode_frame_start(packet);
        check(start_.frame_index == frame->index && start_.width == static_cast<std::uint32_t>(frame->width) &&
                  start_.height == static_cast<std::uint32_t>(frame->height) && start_.bits == frame->bits,
              "FRAME_START does not describe the frame");
        check(start_.flags == kFlagAnswerExpected, "flow control without the answer flag");
        check(start_.chunk_count >= 1 && start_.chunk_data_size >= 1, "no chunks");
        payload_.assign(start_.payload_length, 0);
        next_ = 0;
        resends_this_frame = 0;
        last_answer.reset();
        frame_complete = false;
        state_ = State::Sending;
        return;
      }
      case PacketType::Chunk: {
        const ChunkHeader h = decode_chunk_header(packet);
        if (state_ == State::Answered) {
          // Only a RESEND for this frame, naming a chunk it has, restarts the chunks, at that chunk.
          check(last_answer && last_answer->kind == AnswerKind::Resend &&
                    last_answer->frame_index == start_.frame_index && last_answer->sequence < start_.chunk_count,
                "chunks sent again without a valid RESEND");
          check(h.sequence == last_answer->sequence, "resend does not start at the chunk asked for");
          ++resends_this_frame;
          ++resends_total;
          next_ = h.sequence;
          state_ = State::Sending;
        }
        check(state_ == State::Sending, "CHUNK outside a frame");
        check(h.sequence == next_ && h.sequence < start_.chunk_count, "chunk out of order");
        const std::size_t begin = static_cast<std::size_t>(h.sequence) * start_.chunk_data_size;
        const bool last = h.sequence + 1 == start_.chunk_count;
        check(h.last == last, "last-chunk flag wrong");
        check(begin + h.length <= payload_.size() &&
                  (last ? begin + h.length == payload_.size() : h.length == start_.chunk_data_size),
              "chunk length wrong");
        std::copy(packet.begin() + kChunkHeaderSize, packet.begin() + kChunkHeaderSize + h.length,
                  payload_.begin() + static_cast<std::ptrdiff_t>(begin));
        ++next_;
        return;
      }
      case PacketType::FrameEnd: {
        check(state_ == State::Sending && next_ == start_.chunk_count, "FRAME_END before the last chunk");
        const FrameEnd e = decode_frame_end(packet);
        check(e.frame_index == start_.frame_index && e.chunk_count == start_.chunk_count &&
                  e.payload_crc == start_.payload_crc && crc32_ieee(payload_) == start_.payload_crc,
              "FRAME_END does not match the frame");
        check(payload_ == pack_samples(*frame), "reassembled payload differs from the frame");
        frame_complete = true;
        state_ = State::Answered;
        return;
      }
      default:
        check(false, "unknown packet type sent");
    }
  }

  std::optional<std::vector<std::uint8_t>> receive(std::chrono::milliseconds) override {
    check(state_ == State::Answered, "waiting for an answer before FRAME_END");
    if (input_.empty()) throw RigError(RigErrorKind::Timeout, "fuzz: no more answers");
    const std::uint8_t flags = input_.byte();
    const std::size_t length = input_.byte() % 33;
    std::vector<std::uint8_t> bytes;
    for (std::size_t i = 0; i < length && !input_.empty(); ++i) bytes.push_back(input_.byte());
    if ((flags & 4) && !bytes.empty()) bytes[0] = static_cast<std::uint8_t>(0x81 + bytes[0] % 3);
    if ((flags & 2) && bytes.size() >= 8) {
      std::uint32_t sequence = 0;
      for (int i = 3; i >= 0; --i) sequence = (sequence << 8) | bytes[4 + static_cast<std::size_t>(i)];
      sequence %= start_.chunk_count + 1;
      for (int i = 0; i < 4; ++i) bytes[4 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(sequence >> (8 * i));
    }
    if ((flags & 1) && bytes.size() >= 16) {
      const auto index = static_cast<std::uint64_t>(start_.frame_index);
      for (int i = 0; i < 8; ++i) bytes[8 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(index >> (8 * i));
    }
    const std::optional<Answer> decoded = decode_answer(bytes);
    if (decoded && decoded->frame_index == start_.frame_index) last_answer = decoded;  // what the feeder acts on
    return bytes;
  }

  void frame_done() { state_ = State::Idle; }

 private:
  enum class State { Idle, Sending, Answered };
  Input& input_;
  std::size_t packet_size_;
  State state_ = State::Idle;
  FrameStart start_;
  std::vector<std::uint8_t> payload_;
  std::uint32_t next_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Input input{data, size};
  const int width = 1 + input.byte() % 6, height = 1 + input.byte() % 5, bits = 1 + input.byte() % 16;
  const std::size_t packet_size = kMinPacketSize + input.byte() % 64;
  const int max_resends = input.byte() % 5;
  const int frames = 1 + input.byte() % 3;

  ShadowRig rig(input, packet_size);
  FeedOptions options;
  options.flow_control = true;
  options.max_resends_per_frame = max_resends;
  RigFeeder feeder(rig, options);
  std::int64_t sent = 0;
  for (int k = 0; k < frames; ++k) {
    RigFrame frame;
    frame.index = 1000 + 7 * k;
    frame.eye = k % 2;
    frame.width = width;
    frame.height = height;
    frame.bits = bits;
    frame.samples.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3u);
    for (std::size_t i = 0; i < frame.samples.size(); ++i)
      frame.samples[i] = static_cast<std::uint16_t>((i * 2654435761u + static_cast<std::size_t>(k)) & ((1u << bits) - 1u));
    rig.frame = &frame;
    try {
      check(feeder.feed(frame), "an unpaced frame was dropped");
    } catch (const RigError& e) {
      const std::optional<Answer>& a = rig.last_answer;
      if (e.kind() == RigErrorKind::RigReported) {
        check(rig.frame_complete, "the rig's answer was acted on before the frame was complete");
        check(a && (a->kind == AnswerKind::Error ||
                    (a->kind == AnswerKind::Resend &&
                     (a->sequence >= feeder.stats().interrupted_chunk_count || rig.resends_this_frame >= max_resends))),
              "RigReported without an ERROR or an unusable RESEND");
      } else {
        check(e.kind() == RigErrorKind::Timeout, "unexpected RigError kind");
      }
      check(feeder.stats().frames_sent == sent, "frames_sent counts a frame that failed");
      return 0;
    } catch (...) {
      trm::fuzz::unexpected_exception("fuzz_rig_answers");
    }
    check(rig.frame_complete && rig.last_answer && rig.last_answer->kind == AnswerKind::Ready,
          "a frame counted as sent without a READY for it");
    check(rig.resends_this_frame <= max_resends, "more resends than allowed");
    ++sent;
    rig.frame_done();
    check(feeder.stats().frames_sent == sent && feeder.stats().resends == rig.resends_total, "feeder tally off");
  }
  return 0;
}
