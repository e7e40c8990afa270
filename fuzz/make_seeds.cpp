// Writes the seed corpora of the option, rig-answer, image and video targets, one directory each under
// OUTPUT_DIR (the capture and receiver targets take make_corpus's captures): every accepted form of the
// option texts and a few near misses, answer scripts for READY / RESEND / ERROR, and small images and
// videos written by OpenCV in the formats it can write here.
//
// Usage: make_seeds OUTPUT_DIR
#include "rig/protocol.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

void write(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

void write_texts(const fs::path& dir, const std::vector<std::string>& texts) {
  fs::create_directories(dir);
  for (std::size_t i = 0; i < texts.size(); ++i) write(dir / ("seed_" + std::to_string(i)), texts[i]);
}

// fuzz_rig_answers: configuration bytes, then [flags][length][answer] records.
std::string answer(std::uint8_t flags, std::uint8_t kind, std::uint32_t sequence, std::uint8_t error = 0) {
  std::string a(16, '\0');
  a[0] = static_cast<char>(kind);
  a[1] = static_cast<char>(error);
  for (int i = 0; i < 4; ++i) a[4 + static_cast<std::size_t>(i)] = static_cast<char>(sequence >> (8 * i));
  return std::string(1, static_cast<char>(flags)) + std::string(1, '\x10') + a;
}

void write_rig_answers(const fs::path& dir) {
  fs::create_directories(dir);
  // width 6, height 5, 10 bits (payload 180 bytes), 64-byte packets (4 chunks), 2 resends, 3 frames.
  const std::string config = {'\x05', '\x04', '\x09', '\x00', '\x02', '\x02'};
  const std::string ready = answer(1, 0x81, 0), resend = answer(3, 0x82, 2), error = answer(1, 0x83, 0, 1);
  write(dir / "ready", config + ready + ready + ready);
  write(dir / "resend_then_ready", config + resend + ready + answer(3, 0x82, 0) + ready + ready);
  write(dir / "stale_then_ready", config + answer(0, 0x81, 0) + ready + ready + ready);
  write(dir / "error", config + ready + error);
  write(dir / "resend_past_end", config + answer(1, 0x82, 4));
  write(dir / "too_many_resends", config + resend + resend + resend);
  write(dir / "short_and_foreign", config + std::string("\x01\x03\x81\x00\x00", 5) + answer(1, 0x42, 0) + ready);
  write(dir / "one_pixel_8bit", std::string{'\x00', '\x00', '\x07', '\x3f', '\x00', '\x00'} + ready);
}

// fuzz_rig_stream: what the feeder writes for a few frames, as one byte stream.
void write_rig_streams(const fs::path& dir) {
  using namespace trm::rig;
  fs::create_directories(dir);
  const auto frame = [](std::int64_t index, int width, int height, int bits) {
    RigFrame f;
    f.index = index;
    f.width = width;
    f.height = height;
    f.bits = bits;
    for (int i = 0; i < width * height * 3; ++i) f.samples.push_back(static_cast<std::uint16_t>((i * 37) & ((1 << bits) - 1)));
    return f;
  };
  const auto append = [](std::string& out, const std::vector<std::uint8_t>& packet) { out.append(packet.begin(), packet.end()); };
  const auto stream = [&](const std::vector<RigFrame>& frames, std::size_t packet_size, bool resend) {
    std::string out;
    for (const RigFrame& f : frames) {
      const EncodedFrame e = encode_frame(f, packet_size, false);
      append(out, e.start_packet);
      for (std::uint32_t s = 0; s < e.chunk_count(); ++s) append(out, e.chunk_packet(s));
      if (resend && e.chunk_count() > 1)  // a rewind to chunk 1, as after a RESEND
        for (std::uint32_t s = 1; s < e.chunk_count(); ++s) append(out, e.chunk_packet(s));
      append(out, e.end_packet);
    }
    return out;
  };
  write(dir / "mono_8bit", stream({frame(0, 4, 3, 8)}, 64, false));
  write(dir / "two_frames_10bit", stream({frame(5, 5, 4, 10), frame(6, 5, 4, 10)}, 64, false));
  write(dir / "rewind", stream({frame(9, 6, 5, 12)}, 72, true));
  write(dir / "one_pixel_1bit", stream({frame(1, 1, 1, 1)}, 64, false));
}

cv::Mat pattern(int width, int height, int type) {
  cv::Mat m(height, width, type);
  const int depth = CV_MAT_DEPTH(type), channels = CV_MAT_CN(type);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < channels; ++c) {
        const double v = ((x * 37 + y * 11 + c * 5) % 64) / 63.0;
        if (depth == CV_8U) m.ptr<std::uint8_t>(y)[x * channels + c] = static_cast<std::uint8_t>(v * 255);
        if (depth == CV_16U) m.ptr<std::uint16_t>(y)[x * channels + c] = static_cast<std::uint16_t>(v * 65535);
        if (depth == CV_32F) m.ptr<float>(y)[x * channels + c] = static_cast<float>(v);
      }
  return m;
}

void write_images(const fs::path& dir) {
  fs::create_directories(dir);
  struct Seed {
    const char* name;
    int type;
    std::vector<int> params;
  };
  const std::vector<Seed> seeds = {
      {"rgb8.png", CV_8UC3, {cv::IMWRITE_PNG_COMPRESSION, 9}},
      {"gray8.png", CV_8UC1, {}},
      {"rgba16.png", CV_16UC4, {}},
      {"rgb16.png", CV_16UC3, {}},
      {"rgb8.jpg", CV_8UC3, {cv::IMWRITE_JPEG_QUALITY, 50}},
      {"rgb8.bmp", CV_8UC3, {}},
      {"rgb8.ppm", CV_8UC3, {}},
      {"gray16.pgm", CV_16UC1, {}},
      {"rgb8.tiff", CV_8UC3, {}},
      {"float.tiff", CV_32FC3, {}},
      {"rgb8.webp", CV_8UC3, {cv::IMWRITE_WEBP_QUALITY, 50}},
      {"float.hdr", CV_32FC3, {}},
      {"rgb8.sr", CV_8UC3, {}},
  };
  for (const Seed& s : seeds) {
    try {
      if (!cv::imwrite((dir / s.name).string(), pattern(6, 5, s.type), s.params))
        std::cerr << "make_seeds: OpenCV here cannot write " << s.name << " (skipped)\n";
    } catch (const cv::Exception&) {
      std::cerr << "make_seeds: OpenCV here cannot write " << s.name << " (skipped)\n";
    }
  }
}

void write_videos(const fs::path& dir) {
  fs::create_directories(dir);
  struct Seed {
    const char* name;
    int api;
    const char* fourcc;
  };
  const std::vector<Seed> seeds = {
      {"mjpeg.avi", cv::CAP_OPENCV_MJPEG, "MJPG"},  // OpenCV's own writer: always available
      {"mjpeg_ffmpeg.avi", cv::CAP_FFMPEG, "MJPG"},
      {"ffv1.mkv", cv::CAP_FFMPEG, "FFV1"},
      {"mpeg4.mp4", cv::CAP_FFMPEG, "mp4v"},
  };
  for (const Seed& s : seeds) {
    const std::string path = (dir / s.name).string();
    try {
      const auto fourcc = cv::VideoWriter::fourcc(s.fourcc[0], s.fourcc[1], s.fourcc[2], s.fourcc[3]);
      cv::VideoWriter writer(path, s.api, fourcc, 10.0, cv::Size(16, 8));
      if (!writer.isOpened()) {
        std::cerr << "make_seeds: OpenCV here cannot write " << s.name << " (skipped)\n";
        continue;
      }
      for (int t = 0; t < 3; ++t) {
        cv::Mat frame = pattern(16, 8, CV_8UC3);
        frame += cv::Scalar::all(40 * t);
        writer.write(frame);
      }
    } catch (const cv::Exception&) {
      std::cerr << "make_seeds: OpenCV here cannot write " << s.name << " (skipped)\n";
      fs::remove(path);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_seeds OUTPUT_DIR\n";
    return 2;
  }
  const fs::path out = argv[1];
  try {
    write_texts(out / "link_preset",
                {"dp1.2", "dp1.4", "dp2.1-uhbr10", "dp2.1-uhbr13.5", "dp2.1-uhbr20", "hdmi2.0", "hdmi2.1", "wigig",
                 "wigig:2.5", "usb3-gen1", "usb3-gen2", "custom:10:0.8", "custom:1e-3:1", "custom:10", "custom:x:0.5",
                 "wigig:-1", "dp1.4 "});
    write_texts(out / "panel", {"vive", "rift", "generic", "gamma:2.2", "gamma:2.29,2.25,2.19", "lcd",
                                "lcd:-0.1,0.2,0.5,0,2.2", "lcd:0.3,-0.5,0.2,0.05,2.4", "lcd:1e-30,0,0.5,0,1",
                                "gamma:0", "gamma:1,2", "lcd:1,2,3,4", "gamma:inf", "lcd:0,0,0,0,1"});
    write_texts(out / "view_size", {"1080x1200", "1x1", "64X48", "0x5", "10x", "x10", "10x10x", "-3x4", " 8x 8",
                                    "2147483647x2147483647", "12y12"});
    // fuzz_options: first byte even: --burst, odd: VID:PID.
    write_texts(out / "options", {std::string("\x00") + "1e-7:64", std::string("\x00") + "0:1", std::string("\x00") + "1:1000000",
                                  std::string("\x00") + "0.5:0", std::string("\x00") + "1e-7", std::string("\x01") + "1234:5678",
                                  std::string("\x01") + "0x1d6b:0X0002", std::string("\x01") + "abcd:12345",
                                  std::string("\x01") + "1234"});
    write_rig_answers(out / "rig_answers");
    write_rig_streams(out / "rig_stream");
    write_images(out / "image");
    write_videos(out / "video");
  } catch (const std::exception& e) {
    std::cerr << "make_seeds: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
