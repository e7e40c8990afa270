// Writes the fuzz seed corpus: small but complete .trmcap captures made by the real transmitter and
// capture writer, covering every packetisation, both depths, mono and stereo, raw and JPEG-LS
// payloads, and captures holding damaged and missing packets.
//
// Usage: make_corpus OUTPUT_DIR
#include "trm/capture.hpp"
#include "trm/faults.hpp"
#include "trm/link.hpp"

#include <filesystem>
#include <iostream>
#include <string>

namespace {

using namespace trm;
using namespace trm::link;

cv::Mat codes_for(int width, int height, int bits, int seed) {
  cv::Mat codes(height, width, CV_16UC3);
  const int max_code = (1 << bits) - 1;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      codes.at<cv::Vec3w>(y, x) = cv::Vec3w(static_cast<std::uint16_t>((x * 37 + seed) % (max_code + 1)),
                                            static_cast<std::uint16_t>((y * 11 + x) % (max_code + 1)),
                                            static_cast<std::uint16_t>((x * y + seed * 5) % (max_code + 1)));
  return codes;
}

LinkFrame view(std::int64_t t, int eye, int width, int height, int bits, bool stereo) {
  const bool full = ((t + (stereo ? eye : 0)) % 2) == 0;
  LinkFrame f;
  f.meta.index = t;
  f.meta.eye = eye;
  f.meta.parity = full ? Parity::Full : Parity::Reduced;
  f.meta.full_width = width;
  f.meta.full_height = height;
  f.meta.width = full ? width : std::max(1, (width + 1) / 2);
  f.meta.height = full ? height : std::max(1, (height + 1) / 2);
  f.meta.bits = bits;
  f.codes = codes_for(f.meta.width, f.meta.height, bits, static_cast<int>(t * 2 + eye));
  return f;
}

void write_capture(const std::filesystem::path& path, int width, int height, int bits, bool stereo, int frames,
                   const PacketizerConfig& config, const FaultConfig& faults) {
  Transmitter tx(config);
  FaultInjector injector(faults);
  CaptureWriter writer(path, R"({"scene":"corpus","reduction":0.5})");
  for (int t = 0; t < frames; ++t)
    for (int eye = 0; eye < (stereo ? 2 : 1); ++eye)
      for (auto& packet : tx.send(view(t, eye, width, height, bits, stereo)).packets)
        if (injector.apply(packet)) writer.write_packet(packet);
  writer.close();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_corpus OUTPUT_DIR\n";
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  const FaultConfig clean{};
  const PacketizerConfig one_line{}, three_lines{3, 1 << 16, PayloadCoding::Raw}, slices{1, 16, PayloadCoding::Raw};
  const PacketizerConfig jls_slice{4, 0, PayloadCoding::JpegLs}, jls_frame{1 << 16, 0, PayloadCoding::JpegLs};
  try {
    write_capture(dir / "mono_8bit.trmcap", 8, 6, 8, false, 2, one_line, clean);
    write_capture(dir / "stereo_10bit.trmcap", 7, 5, 10, true, 2, one_line, clean);
    write_capture(dir / "stereo_multiline.trmcap", 9, 7, 8, true, 2, three_lines, clean);
    write_capture(dir / "slices_10bit.trmcap", 11, 3, 10, false, 2, slices, clean);
    write_capture(dir / "jpegls_slices.trmcap", 12, 8, 8, true, 2, jls_slice, clean);
    write_capture(dir / "jpegls_frame_10bit.trmcap", 10, 6, 10, false, 2, jls_frame, clean);
    write_capture(dir / "one_pixel.trmcap", 1, 1, 8, true, 3, one_line, clean);
    write_capture(dir / "damaged.trmcap", 8, 6, 10, true, 3, one_line, FaultConfig{2e-3, {}, 0.1, 5});
    write_capture(dir / "bursts.trmcap", 8, 6, 8, false, 3, one_line, FaultConfig{0.0, {1e-3, 40}, 0.0, 6});
  } catch (const std::exception& e) {
    std::cerr << "make_corpus: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
