// libFuzzer target for the capture reader alone. The input is a .trmcap file. The reader must either
// throw CaptureError or yield packets that fit the file; a capture it accepts in full is canonical, so
// writing its metadata and packets again with CaptureWriter must reproduce the input byte for byte.
#include "fuzz_support.hpp"
#include "trm/capture.hpp"

#include <cstring>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using trm::fuzz::check;
using namespace trm::link;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string metadata;
  std::vector<std::vector<std::uint8_t>> packets;
  std::size_t bytes = 0;
  try {
    CaptureReader reader(std::make_unique<std::istringstream>(std::string(reinterpret_cast<const char*>(data), size)));
    metadata = reader.metadata();
    check(metadata.size() <= kCaptureMaxMetadataBytes, "metadata longer than the format allows");
    while (auto packet = reader.next_packet()) {
      check(!packet->empty() && packet->size() <= kCaptureMaxPacketBytes, "packet length outside the format");
      bytes += kCaptureRecordHeaderBytes + packet->size();
      check(kCaptureHeaderBytes + metadata.size() + bytes <= size, "packets larger than the file");
      packets.push_back(std::move(*packet));
      check(reader.packets_read() == packets.size(), "packets_read() off");
    }
    check(!reader.next_packet().has_value(), "a packet after the end record");
  } catch (const CaptureError&) {
    return 0;  // malformed capture: the documented outcome
  } catch (...) {
    trm::fuzz::unexpected_exception("fuzz_capture");
  }

  // Accepted in full: re-encode and compare.
  const std::filesystem::path path = trm::fuzz::scratch_dir() / "roundtrip.trmcap";
  {
    CaptureWriter writer(path, metadata);
    for (const auto& packet : packets) writer.write_packet(packet);
    writer.close();
  }
  std::ifstream in(path, std::ios::binary);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  check(written.size() == size && std::memcmp(written.data(), data, size) == 0,
        "an accepted capture is not what CaptureWriter writes for its contents");
  return 0;
}
