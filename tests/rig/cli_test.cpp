// `trm feed` end to end with frames from the real pipeline: the trm process inherits the testbed
// (UMOCKDEV_DIR, LD_PRELOAD), so its libusb calls reach the emulated rig in this process.
#include "emulated_bench.hpp"
#include "rig_test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sys/wait.h>

#ifdef TRM_BINARY

namespace trm::rig::testing {
namespace {

const std::string kScene = " --scene discs --size 40x30 --frames 3 --fps 0 --chunk 512";

int run_trm(const std::string& arguments) {
  const std::string command = std::string("timeout 120 ") + TRM_BINARY + " " + arguments + " > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::vector<std::uint8_t> slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string temp_path(const char* name) { return "/tmp/trm-rig-" + std::to_string(::getpid()) + "-" + name; }

TEST(TrmFeed, FileOutputOfASceneIsByteIdenticalToWhatTheUsbRigReceived) {
  EmulatedBench bench;
  bench.add_bulk_rig();
  const std::string file = temp_path("scene.bin"), summary = temp_path("summary.json");
  ASSERT_EQ(run_trm("feed --usb 1234:5678" + kScene + " --summary " + summary), 0);
  ASSERT_EQ(run_trm("feed --file " + file + kScene), 0);
  const auto written = slurp(file);
  const auto report = nlohmann::json::parse(slurp(summary));
  ::unlink(file.c_str());
  ::unlink(summary.c_str());
  ASSERT_FALSE(written.empty());
  EXPECT_EQ(written, bench.bulk_received());
  const auto frames = receive_stream(written);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[2].index, 2);
  EXPECT_EQ(frames[0].width, 40);
  EXPECT_EQ(frames[0].height, 30);
  EXPECT_EQ(report["status"], "ok");
  EXPECT_EQ(report["stats"]["frames_sent"], 3);
  EXPECT_EQ(report["stats"]["wire_bytes_sent"], written.size());
}

// Whole views are packed in place from the decoder's output plane; a region is copied out first. The
// codes that arrive must not depend on which of the two paths carried them.
TEST(TrmFeed, ViewsPackedInPlaceCarryTheSameCodesAsTheCopiedWholeRegion) {
  const std::string whole = temp_path("whole.bin"), region = temp_path("region.bin");
  ASSERT_EQ(run_trm("feed --file " + whole + kScene), 0);
  ASSERT_EQ(run_trm("feed --file " + region + kScene + " --roi 0,0,40,30"), 0);
  const auto in_place = receive_stream(slurp(whole));
  const auto copied = receive_stream(slurp(region));
  ::unlink(whole.c_str());
  ::unlink(region.c_str());
  ASSERT_EQ(in_place.size(), 3u);
  ASSERT_EQ(copied.size(), 3u);
  for (std::size_t i = 0; i < in_place.size(); ++i) {
    EXPECT_EQ(in_place[i].index, copied[i].index);
    EXPECT_EQ(in_place[i].width, copied[i].width);
    EXPECT_EQ(in_place[i].height, copied[i].height);
    EXPECT_EQ(in_place[i].samples, copied[i].samples) << "view " << i;
  }
  std::uint16_t any_code = 0;
  for (const std::uint16_t c : in_place[1].samples) any_code |= c;
  EXPECT_NE(any_code, 0) << "a scene of discs drives some subpixel";
}

TEST(TrmFeed, UnpluggedRigGivesItsExitCodeAndTheSummarySaysHowFarItGot) {
  RigBehaviour rig;
  rig.fault = Fault::Vanish;
  rig.fault_after_bytes = 5000;
  EmulatedBench bench;
  bench.add_bulk_rig(rig);
  const std::string summary = temp_path("unplug.json");
  EXPECT_EQ(run_trm("feed --usb 1234:5678" + kScene + " --summary " + summary), static_cast<int>(RigErrorKind::Disconnected));
  const auto report = nlohmann::json::parse(slurp(summary));
  ::unlink(summary.c_str());
  EXPECT_EQ(report["status"], "error");
  EXPECT_EQ(report["error"]["kind"], "disconnected");
  EXPECT_EQ(report["stats"]["wire_bytes_sent"], bench.bulk_received().size());
  EXPECT_TRUE(report["stats"].contains("interrupted"));
}

TEST(TrmFeed, NoDeviceIsAClearErrorNotACrash) {
  EmulatedBench bench;
  EXPECT_EQ(run_trm("feed --usb 1234:5678" + kScene), static_cast<int>(RigErrorKind::NoDevice));
  EXPECT_EQ(run_trm("feed --hid 1234:5679" + kScene), static_cast<int>(RigErrorKind::NoDevice));
}

TEST(TrmFeed, ListWithNoDevicesSaysSoAndExitsZero) {
  EmulatedBench bench;
  const std::string out = temp_path("list.txt");
  const int status = std::system((std::string(TRM_BINARY) + " feed --list > " + out).c_str());
  const auto text = slurp(out);
  ::unlink(out.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_NE(std::string(text.begin(), text.end()).find("No USB or HID devices found"), std::string::npos);
}

}  // namespace
}  // namespace trm::rig::testing

#endif
