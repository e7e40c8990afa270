// libFuzzer target for the link receiver. The input is a .trmcap capture file: every packet the
// capture reader yields goes to two receivers, one as stored (so damage stops at the CRC) and one with
// the CRC recomputed (so mutations reach the header checks, reassembly and the JPEG-LS decoder).
// Any crash, sanitizer report, or broken invariant of a handed-out frame is a finding.
#include "trm/capture.hpp"
#include "trm/link.hpp"
#include "trm/packet.hpp"

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>

namespace {

using namespace trm::link;

// Small limits keep every input fast and within the fuzzer's memory budget.
constexpr ReceiverLimits kLimits{1024, 1024, 1u << 18};

void check(bool condition) {
  if (!condition) std::abort();
}

void drain(Receiver& rx) {
  for (const ReceivedFrame& f : rx.take_frames()) {
    check(f.codes.type() == CV_16UC3);
    check(f.codes.rows == f.meta.height && f.codes.cols == f.meta.width);
    check(f.meta.width >= 1 && f.meta.width <= kLimits.max_width);
    check(f.meta.height >= 1 && f.meta.height <= kLimits.max_height);
    check(f.line_intact.size() == static_cast<std::size_t>(f.meta.height));
    const int max_code = (1 << f.meta.bits) - 1;
    for (int y = 0; y < f.meta.height; ++y) {
      const auto* row = f.codes.ptr<std::uint16_t>(y);
      for (int i = 0; i < f.meta.width * 3; ++i) {
        check(row[i] <= max_code);
        if (!f.line_intact[static_cast<std::size_t>(y)]) check(row[i] == 0);
      }
    }
  }
}

void repair_crc(std::vector<std::uint8_t>& packet) {
  if (packet.size() < kPacketCrcBytes) return;
  const std::uint32_t crc = packet_crc(packet);
  for (std::size_t i = 0; i < 4; ++i) packet[packet.size() - 4 + i] = static_cast<std::uint8_t>(crc >> (8 * i));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Receiver as_stored(kLimits), repaired(kLimits);
  try {
    CaptureReader reader(std::make_unique<std::istringstream>(std::string(reinterpret_cast<const char*>(data), size)));
    while (auto packet = reader.next_packet()) {
      as_stored.push(*packet);
      repair_crc(*packet);
      repaired.push(*packet);
      drain(as_stored);
      drain(repaired);
    }
  } catch (const CaptureError&) {
    // A malformed capture is expected input; what was read before the error has been processed.
  }
  for (Receiver* rx : {&as_stored, &repaired}) {
    rx->flush();
    drain(*rx);
    const ReceiverCounters& c = rx->counters();
    check(c.packets_accepted + c.crc_failures + c.malformed + c.inconsistent + c.duplicates + c.stale ==
          c.packets_received);
    check(c.frames_complete + c.frames_partial == c.frames_out);
  }
  return 0;
}
