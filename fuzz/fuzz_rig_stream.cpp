// libFuzzer target for the rig side of the protocol: split_stream and the reference StreamReceiver (the
// executable form of what docs/rig_protocol.md says a rig checks). The input is a byte stream as a bulk
// rig or a --file receives it. Each packet goes to the receiver with its FRAME_START / FRAME_END header
// CRC recomputed, so mutations reach the checks behind it. The receiver must reject a malformed packet
// with std::runtime_error and carry on with the next; every frame it hands out must be a valid RigFrame
// that the feeder's encoder turns back into the payload it was reassembled from.
#include "fuzz_support.hpp"
#include "rig/protocol.hpp"

#include <stdexcept>
#include <vector>

using trm::fuzz::check;
using namespace trm::rig;

namespace {

void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

void repair_header_crc(std::vector<std::uint8_t>& packet) {
  if (packet[0] == static_cast<std::uint8_t>(PacketType::FrameStart) && packet.size() >= kFrameStartSize)
    put_u32(&packet[60], crc32_ieee(std::span(packet).first(60)));
  if (packet[0] == static_cast<std::uint8_t>(PacketType::FrameEnd) && packet.size() >= kFrameEndSize)
    put_u32(&packet[20], crc32_ieee(std::span(packet).first(20)));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::vector<std::uint8_t>> packets;
  try {
    packets = split_stream({data, size});
  } catch (const std::runtime_error&) {
    return 0;  // not a stream of whole packets
  } catch (...) {
    trm::fuzz::unexpected_exception("fuzz_rig_stream");
  }
  StreamReceiver receiver;
  for (auto& packet : packets) {
    check(!packet.empty(), "split_stream gave an empty packet");
    repair_header_crc(packet);
    try {
      receiver.accept_packet(packet);
    } catch (const std::runtime_error&) {
      // Malformed or out of place: a rig drops it and goes on.
    } catch (...) {
      trm::fuzz::unexpected_exception("fuzz_rig_stream");
    }
  }
  for (const RigFrame& frame : receiver.frames()) {
    try {
      frame.validate();
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "handed-out frame is invalid: %s\n", e.what());
      std::abort();
    }
    const EncodedFrame again = encode_frame(frame, kMinPacketSize, false);
    check(again.payload.size() == frame.payload_size(), "frame re-encodes to another payload size");
  }
  return 0;
}
