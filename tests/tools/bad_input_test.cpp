// Crash freedom through the real `trm` binary: every bad-input class (issue list "nothing crashes, hangs, clobbers or
// lies", and the classes handled before it) exits 1..127 with exactly one "trm: error:" line naming the option or
// file, and leaves no file behind: the working directory stays empty and the fixtures the case reads stay as they
// were.
#include "trm/capture.hpp"
#include "trm/packet.hpp"
#include "trm_process.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace trm {
namespace {

using test::ScratchDir;

struct Outcome {
  int exit_code = -1;
  std::string out, err;
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Runs trm in `cwd` with stdout and stderr captured apart (in files outside cwd), for at most a minute.
Outcome run_in(const fs::path& cwd, const fs::path& capture_dir, const std::string& args) {
  const fs::path out = capture_dir / "stdout", err = capture_dir / "stderr";
  // A hang is a failure of its own (exit 124 from timeout), not a stalled suite.
  // TRM_BAD_INPUT_EXECUTABLE runs the table against another build (an older one shows which classes it fails).
  const char* other = std::getenv("TRM_BAD_INPUT_EXECUTABLE");
  const std::string executable = other != nullptr && *other != '\0' ? other : TRM_EXECUTABLE;
  const std::string command = "cd '" + cwd.string() + "' && exec timeout --kill-after=5 60 " + executable + " " +
                              args + " >'" + out.string() + "' 2>'" + err.string() + "' </dev/null";
  const int status = std::system(command.c_str());
  Outcome o;
  o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.out = read_text(out);
  o.err = read_text(err);
  return o;
}

// Every entry below `root` with its size and modification time: what "untouched" means.
std::map<std::string, std::string> snapshot(const fs::path& root) {
  std::map<std::string, std::string> entries;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    std::error_code ec;
    const auto size = e.is_regular_file(ec) ? e.file_size(ec) : 0;
    const auto time = fs::last_write_time(e.path(), ec).time_since_epoch().count();
    entries[fs::relative(e.path(), root).string()] = std::to_string(size) + "@" + std::to_string(time);
  }
  return entries;
}

std::vector<std::string> error_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.find("trm: error:") != std::string::npos) lines.push_back(line);
  }
  return lines;
}

// Rewrites a capture: `metadata` replaces the header's configuration, `keep` selects the packets.
void rewrite_capture(const fs::path& in, const fs::path& out, const std::string& metadata,
                     const std::function<bool(const link::PacketHeader&)>& keep) {
  link::CaptureReader reader(in);
  link::CaptureWriter writer(out, metadata);
  while (auto packet = reader.next_packet()) {
    link::PacketError error{};
    const auto parsed = link::parse_packet(*packet, link::ReceiverLimits{}, &error);
    if (!parsed || keep(parsed->header)) writer.write_packet(*packet);
  }
  writer.close();
}

std::string with(const std::string& metadata, const std::string& key, const nlohmann::json& value) {
  nlohmann::json j = nlohmann::json::parse(metadata);
  j[key] = value;
  return j.dump();
}

class BadInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    fixtures_ = std::make_unique<ScratchDir>("trm-bad-input-fixtures-");
    const fs::path f = fixtures_->path();
    std::ofstream(f / "not_a_hid") << "a regular file\n";
    ASSERT_EQ(::mkfifo((f / "fifo").c_str(), 0600), 0);
    fs::create_symlink(f / "not_a_hid", f / "symlink");
    fs::create_directories(f / "project");
    std::ofstream(f / "project" / "report.json") << "{\"mine\": true}\n";  // a user's file, not a trm output
    std::ofstream(f / "project" / "main.cpp") << "int main() {}\n";
    fs::create_directories(f / "frames_dir");
    for (const bool stereo : {false, true}) {
      const std::string name = stereo ? "stereo" : "mono";
      const auto r = test::run_trm("run --scene discs --size 16x12 --frames 6 --link dp1.4 " +
                                   std::string(stereo ? "--stereo " : "") + "--capture-out " +
                                   (f / (name + ".trmcap")).string() + " --out " + (f / ("run_" + name)).string());
      ASSERT_EQ(r.exit_code, 0) << r.output;
    }
    const std::string mono_meta = link::CaptureReader(f / "mono.trmcap").metadata();
    const std::string stereo_meta = link::CaptureReader(f / "stereo.trmcap").metadata();
    const auto all = [](const link::PacketHeader&) { return true; };
    rewrite_capture(f / "mono.trmcap", f / "refresh_negative.trmcap", with(mono_meta, "refresh_hz", -1), all);
    rewrite_capture(f / "mono.trmcap", f / "refresh_zero.trmcap", with(mono_meta, "refresh_hz", 0), all);
    rewrite_capture(f / "mono.trmcap", f / "says_stereo.trmcap", with(mono_meta, "stereo", true), all);
    rewrite_capture(f / "stereo.trmcap", f / "says_mono.trmcap", with(stereo_meta, "stereo", false), all);
    rewrite_capture(f / "mono.trmcap", f / "says_r2.trmcap", with(mono_meta, "reduction", 2.0), all);
    rewrite_capture(f / "mono.trmcap", f / "says_phase1.trmcap", with(mono_meta, "phase", 1), all);
    rewrite_capture(f / "mono.trmcap", f / "beyond_frames.trmcap", with(mono_meta, "frames", 3), all);
    rewrite_capture(f / "mono.trmcap", f / "no_frames.trmcap", mono_meta, [](const link::PacketHeader&) { return false; });
  }
  static void TearDownTestSuite() { fixtures_.reset(); }

  // Runs one bad case and checks the whole contract.
  void expect_clean_failure(const std::string& args, const std::string& fragment) {
    SCOPED_TRACE("trm " + args);
    ScratchDir scratch("trm-bad-input-");
    const fs::path cwd = scratch.path() / "cwd";
    fs::create_directories(cwd);
    const auto before = snapshot(fixtures_->path());
    std::string expanded = args;
    for (std::size_t at; (at = expanded.find("{f}")) != std::string::npos;) {
      expanded.replace(at, 3, fixtures_->path().string());
    }
    const Outcome o = run_in(cwd, scratch.path(), expanded);
    EXPECT_NE(o.exit_code, 124) << "timed out after 60 s";
    EXPECT_GE(o.exit_code, 1) << o.err;
    EXPECT_LE(o.exit_code, 127) << o.err;
    const auto lines = error_lines(o.err);
    ASSERT_EQ(lines.size(), 1u) << "stderr:\n" << o.err << "stdout:\n" << o.out;
    EXPECT_EQ(lines[0].rfind("trm: error: ", 0), 0u) << lines[0];
    EXPECT_NE(lines[0].find(fragment), std::string::npos) << lines[0];
    EXPECT_TRUE(fs::is_empty(cwd)) << "left behind: " << fs::directory_iterator(cwd)->path();
    EXPECT_EQ(snapshot(fixtures_->path()), before);
  }

  static std::unique_ptr<ScratchDir> fixtures_;
};

std::unique_ptr<ScratchDir> BadInput::fixtures_;

struct Case {
  std::string args;
  std::string fragment;  // what the one error line must name
};

// Unknown names in the options every pipeline command shares: never an abort, in any subcommand.
TEST_F(BadInput, UnknownNamesInSharedOptions) {
  for (const std::string command :
       {"run --size 32x24 --frames 2", "decode --input '{f}/frames_dir/*.png' --out o", "feed --file o.bin",
        "hw-report", "vectors --out o", "sweep --quick --out o"}) {
    expect_clean_failure(command + " --transfer foo", "--transfer");
    expect_clean_failure(command + " --resample-space sideways", "--resample-space");
    expect_clean_failure(command + " --panel oled", "panel");
    expect_clean_failure(command + " --size 4294967297x1", "--size");
  }
}

TEST_F(BadInput, NumbersOutOfRange) {
  const std::vector<Case> cases = {
      {"run --size 4294967297x1 --frames 2", "--size"},
      {"run --size 0x4 --frames 2", "--size"},
      {"run --size 65536x2 --frames 2", "--size"},
      {"run --size 32x-1 --frames 2", "--size"},
      {"run --size 32x24x2 --frames 2", "--size"},
      {"run --size 65535x65535 --frames 2", "memory"},
      {"run --size 65535x65535 --frames 2 --stereo --panel lcd", "in stereo"},
      {"lossless --size 65535x65535 --frames 2", "memory"},
      {"sweep --size 65535x65535 --out o", "recorded views"},
      {"sweep --quick --size 4096x4096 --frames 100000 --out o", "100000 recorded views"},
      {"run -r 1.0000001 --size 8x8 --frames 2", "1.0000001"},
      {"run -r 0 --size 8x8 --frames 2", "--reduction"},
      {"run --sigma 1e-160 --size 8x8 --frames 2", "--sigma"},
      {"run --sigma nan --size 8x8 --frames 2", "--sigma"},
      {"run --sigma 1e10 --size 8x8 --frames 2", "--sigma"},
      {"run --frames 0 --size 8x8", "--frames"},
      {"run --frames -3 --size 8x8", "--frames"},
      {"vectors --frames 0 --out o", "--frames"},
      {"lossless --frames 0", "--frames"},
      {"lossless --frames 1", "--frames"},
      {"run --refresh 0 --size 8x8 --frames 2", "--refresh"},
      {"run --refresh nan --size 8x8 --frames 2", "--refresh"},
      {"run --link dp1.2 --refresh 1e-298 --size 8x8 --frames 2", "--refresh"},
      {"run --link custom:1e300:1 --size 8x8 --frames 2", "custom:1e300:1"},
      {"run --link custom:10:0 --size 8x8 --frames 2", "custom:10:0"},
      {"run --link wigig:inf --size 8x8 --frames 2", "wigig:inf"},
      {"run --ber -1 --size 8x8 --frames 2", "--ber"},
      {"run --ber nan --size 8x8 --frames 2", "--ber"},
      {"run --drop -0.1 --size 8x8 --frames 2", "--drop"},
      {"run --burst 1e-7:0 --size 8x8 --frames 2", "--burst"},
      {"run --sensitivity -1 --size 8x8 --frames 2", "sensitivity"},
      {"run --sensitivity 1e308 --impl reference --size 8x8 --frames 2", "--sensitivity"},
      {"run --bits 12 --size 8x8 --frames 2", "bits"},
      {"feed --fps -1 --size 8x8 --frames 2 --file o.bin", "--fps"},
      {"feed --fps nan --size 8x8 --frames 2 --file o.bin", "--fps"},
      {"sweep --quick --size 16x12 --knob linear_frac_bits --values 14,16 --out o", "--values"},
  };
  for (const Case& c : cases) expect_clean_failure(c.args, c.fragment);
}

// Panels the formats or the physics cannot serve are refused by every decoder, naming the panel or the stage.
TEST_F(BadInput, PanelsNoDecoderCanServe) {
  for (const std::string impl : {"reference", "fixed", "fixed-frame"}) {
    for (const std::string panel : {"lcd:0,0,0,0,2.2", "lcd:-1,2,0.5,0,2.2", "gamma:1e308", "gamma:0.1", "lcd:20,0,0.5,0,2.2"}) {
      expect_clean_failure("run --impl " + impl + " --panel " + panel + " --size 8x8 --frames 2", panel);
    }
  }
  // A valid panel whose p3 the fixed-point registers round to 0: the fixed decoders name the stage.
  for (const std::string impl : {"fixed", "fixed-frame"}) {
    expect_clean_failure("run --impl " + impl + " --panel lcd:0,0,1e-9,0,2.2 --size 8x8 --frames 2",
                         "LCD drive (merge coefficients");
  }
}

TEST_F(BadInput, FeedRegionsAndDevices) {
  const std::vector<Case> cases = {
      {"feed --roi 2147483647,0,1,1 --size 32x24 --frames 2 --file o.bin", "--roi"},
      {"feed --roi 0,2147483647,1,1 --size 32x24 --frames 2 --file o.bin", "--roi"},
      {"feed --roi 1,0,2147483647,1 --size 32x24 --frames 2 --file o.bin", "--roi"},
      {"feed --roi 1,0,99999999999,1 --size 32x24 --frames 2 --file o.bin", "--roi"},
      {"feed --roi 30,0,4,1 --size 32x24 --frames 2 --file o.bin", "--roi"},
      {"feed --roi 1,2,3 --size 32x24 --frames 2 --file o.bin", "--roi"},
      {"feed --hid {f}/not_a_hid --size 8x8 --frames 2", "--hid"},
      {"feed --hid /dev/zero --size 8x8 --frames 2", "--hid"},
      {"feed --hid {f}/frames_dir --size 8x8 --frames 2", "--hid"},
  };
  for (const Case& c : cases) expect_clean_failure(c.args, c.fragment);
}

TEST_F(BadInput, InputsThatAreNotInputs) {
  const std::vector<Case> cases = {
      {"run --input {f}/frames_dir --frames 2", "is a directory"},
      {"run --input {f}/missing.mp4 --frames 2", "does not exist"},
      {"run --input '{f}/frames_dir/*.png'", "frames_dir"},
      {"run --scene nosuch --size 8x8 --frames 2", "nosuch"},
      {"run --impl nosuch --size 8x8 --frames 2", "--impl"},
      {"run --method nosuch --size 8x8 --frames 2", "--method"},
      {"compare --methods trm,nosuch --size 8x8 --frames 2", "--methods"},
      {"compare --methods bfi,bfi --size 8x8 --frames 2", "named twice"},
      {"compare --ppd 0 --size 8x8 --frames 2", "--ppd"},
      {"compare --ppd nan --size 8x8 --frames 2", "--ppd"},
      {"compare --viewer cardboard --size 8x8 --frames 2", "--viewer"},
      {"compare --substeps -3 --size 8x8 --frames 2", "--substeps"},
      {"compare --speed nan --size 8x8 --frames 2", "--speed"},
      {"compare --speed -1 --size 8x8 --frames 2", "--speed"},
      {"compare --speed 5 --scene static --size 8x8 --frames 2", "no moving target"},
      {"compare --speed 5 --scene jitter --size 8x8 --frames 2", "has no motion whose speed can be set"},
      {"run --method interlace:triple --size 8x8 --frames 2", "--method"},
      {"run --method bfi: --size 8x8 --frames 2", "--method"},
      {"run --method kim:d=2 --size 8x8 --frames 2", "d must be in [0, 1]"},
      {"compare --methods kim:wmin=0.05 --size 8x8 --frames 2", "wlb <= wmin"},
      {"run --method full --impl fixed --size 8x8 --frames 2", "--method"},
      {"run --method interlace --size 8x1 --frames 2", "2 rows"},
      {"decode --out o", "--input"},
      {"decode --capture {f}/missing.trmcap --out o", "missing.trmcap"},
      {"decode --capture {f}/not_a_hid --out o", "not_a_hid"},
  };
  for (const Case& c : cases) expect_clean_failure(c.args, c.fragment);
}

// Capture headers are held to the rules of the options that wrote them.
TEST_F(BadInput, CaptureMetadataTheCommandLineWouldReject) {
  const std::vector<Case> cases = {
      {"decode --capture {f}/refresh_negative.trmcap --out o", "refresh_hz"},
      {"decode --capture {f}/refresh_zero.trmcap --out o", "refresh_hz"},
      {"decode --capture {f}/says_stereo.trmcap --out o", "stereo"},
      {"decode --capture {f}/says_mono.trmcap --out o", "mono"},
      {"decode --capture {f}/says_r2.trmcap --out o", "reduction"},
      {"decode --capture {f}/says_phase1.trmcap --out o", "phase"},
      {"decode --capture {f}/beyond_frames.trmcap --out o", "beyond the 3 frames"},
      {"decode --capture {f}/no_frames.trmcap --out o", "no frame that arrived"},
      {"feed --capture {f}/says_mono.trmcap --file o.bin", "mono"},
  };
  for (const Case& c : cases) expect_clean_failure(c.args, c.fragment);
}

// Outputs go onto a regular file or a new name only, and never replace what trm did not write.
TEST_F(BadInput, OutputsThatWouldClobber) {
  const std::vector<Case> cases = {
      {"run --size 8x8 --frames 2 --link dp1.4 --capture-out {f}/fifo --out o", "fifo"},
      {"run --size 8x8 --frames 2 --link dp1.4 --capture-out {f}/symlink --out o", "symlink"},
      {"hw-report --json {f}/fifo", "fifo"},
      {"hw-report --json {f}/frames_dir", "frames_dir"},
      {"vectors --update-golden {f}/fifo", "fifo"},
      {"run --size 8x8 --frames 2 --out {f}/project", "project"},
      {"run --size 8x8 --frames 2 --out {f}/not_a_hid", "not_a_hid"},
      {"feed --size 8x8 --frames 2 --file {f}/fifo", "fifo"},
      {"feed --size 8x8 --frames 2 --file o.bin --summary /nonexistent/s.json", "/nonexistent/s.json"},
      {"feed --size 8x8 --frames 2 --file o.bin --summary {f}/fifo", "fifo"},
  };
  for (const Case& c : cases) expect_clean_failure(c.args, c.fragment);
}

// A view that lost every packet is what the panel shows too (its previous output, held): written and counted.
// The plugin that reads and writes image files (trm/media.hpp) missing, or a library that is not it: one error
// naming it and what was tried, no output.
TEST_F(BadInput, MediaPluginThatCannotBeLoaded) {
  struct PluginVariable {
    explicit PluginVariable(const char* value) { ::setenv("TRM_MEDIA_PLUGIN", value, 1); }
    ~PluginVariable() { ::unsetenv("TRM_MEDIA_PLUGIN"); }
  };
  const std::string reads_an_image = "run --input '{f}/run_mono/pair_sent_full.png' --frames 2 --out o";
  const std::string writes_images = "run --scene discs --size 16x12 --frames 2 --out o";
  {
    const PluginVariable missing("/nonexistent/libtrm_media.so");
    expect_clean_failure(reads_an_image, "libtrm_media.so (it reads and writes image and video files");
    expect_clean_failure(writes_images, "/nonexistent/libtrm_media.so: cannot open shared object file");
  }
  {
    const PluginVariable not_the_plugin("libz.so.1");
    expect_clean_failure(reads_an_image, "libz.so.1: no symbol trm_media_plugin_api");
  }
}

TEST_F(BadInput, LostViewsAreWrittenAndCounted) {
  ScratchDir scratch("trm-lost-view-");
  const fs::path f = fixtures_->path();
  for (const bool stereo : {false, true}) {
    const std::string name = stereo ? "stereo" : "mono";
    const fs::path cut = scratch.path() / (name + "_cut.trmcap");
    // Frame 2 lost whole (both eyes in stereo), and the last frame's left view.
    rewrite_capture(f / (name + ".trmcap"), cut, link::CaptureReader(f / (name + ".trmcap")).metadata(),
                    [](const link::PacketHeader& h) {
                      return h.frame_index != 2 && !(h.frame_index == 5 && h.stream == 0);
                    });
    const fs::path out = scratch.path() / ("out_" + name);
    const auto r = test::run_trm("decode --capture " + cut.string() + " --out " + out.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const int eyes = stereo ? 2 : 1;
    for (int t = 0; t < 6; ++t) {
      for (int eye = 0; eye < eyes; ++eye) {
        char file[64];
        std::snprintf(file, sizeof file, "drive8%s_%04d.png", eye == 0 ? "" : "_right", t);
        EXPECT_TRUE(fs::exists(out / file)) << name << ": " << file;
      }
    }
    const nlohmann::json report = nlohmann::json::parse(read_text(out / "report.json"));
    EXPECT_EQ(report["summary"]["views"].get<int>(), 6 * eyes) << name;
    EXPECT_EQ(report["summary"]["lost_views"].get<int>(), eyes + 1) << name;
    EXPECT_NE(r.output.find(std::to_string(eyes + 1) + " views lost and held"), std::string::npos) << r.output;
    // The held view repeats the previous view of its eye exactly.
    EXPECT_EQ(read_text(out / "drive8_0002.png"), read_text(out / "drive8_0001.png")) << name;
  }
}

// The hardware report at W·H >= 2^31 (cv::Size::area() overflows an int there).
TEST_F(BadInput, HardwareReportAtHugeSizesIsNotZero) {
  ScratchDir scratch("trm-hw-huge-");
  const auto r = test::run_trm("hw-report --size 65535x65535 --json " + scratch.str("hw.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json hw = nlohmann::json::parse(read_text(scratch.path() / "hw.json"));
  const nlohmann::json& per_pixel = hw.contains("hardware") ? hw["hardware"]["arithmetic_per_output_pixel"]
                                                             : hw["arithmetic_per_output_pixel"];
  ASSERT_TRUE(per_pixel.is_object()) << hw.dump().substr(0, 400);
  // The same configuration at 64x64 costs the same per output pixel up to the border terms.
  const auto small = test::run_trm("hw-report --size 64x64 --json " + scratch.str("small.json"));
  ASSERT_EQ(small.exit_code, 0) << small.output;
  const nlohmann::json hw_small = nlohmann::json::parse(read_text(scratch.path() / "small.json"));
  const nlohmann::json& small_per_pixel = hw_small.contains("hardware")
                                              ? hw_small["hardware"]["arithmetic_per_output_pixel"]
                                              : hw_small["arithmetic_per_output_pixel"];
  for (const char* kind : {"full", "reduced"}) {
    const double huge_adders = per_pixel[kind]["adders"].get<double>();
    EXPECT_GT(huge_adders, 0.0) << kind;
    EXPECT_NEAR(huge_adders, small_per_pixel[kind]["adders"].get<double>(),
                0.1 * small_per_pixel[kind]["adders"].get<double>())
        << kind;
  }
}

}  // namespace
}  // namespace trm
