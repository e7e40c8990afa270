// .trmcap captures: round trip, and a clear CaptureError (never a crash) for truncation and corruption.
#include "trm/capture.hpp"
#include "trm/link.hpp"

#include "link_test_support.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace trm::link {
namespace {

using test_support::out_dir;

std::vector<std::vector<std::uint8_t>> sample_packets() {
  Transmitter tx;
  std::vector<std::vector<std::uint8_t>> packets;
  for (int t = 0; t < 2; ++t)
    for (int eye = 0; eye < 2; ++eye)
      for (auto& p : tx.send(test_support::make_view(t, eye, 12, 4, 0.5, 10)).packets) packets.push_back(std::move(p));
  return packets;
}

std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Reads a whole capture held in memory; returns the packets or throws CaptureError.
std::vector<std::vector<std::uint8_t>> read_all(const std::string& bytes, std::string* metadata = nullptr) {
  CaptureReader reader(std::make_unique<std::istringstream>(bytes));
  if (metadata) *metadata = reader.metadata();
  std::vector<std::vector<std::uint8_t>> packets;
  while (auto p = reader.next_packet()) packets.push_back(std::move(*p));
  return packets;
}

std::string write_sample(const std::string& name) {
  const auto path = out_dir() / name;
  CaptureWriter writer(path, R"({"reduction":0.5,"stereo":true})");
  for (const auto& p : sample_packets()) writer.write_packet(p);
  writer.close();
  return file_bytes(path);
}

TEST(Capture, RoundTripKeepsMetadataAndEveryPacket) {
  const auto path = out_dir() / "roundtrip.trmcap";
  write_sample("roundtrip.trmcap");
  CaptureReader reader(path);
  EXPECT_EQ(reader.metadata(), R"({"reduction":0.5,"stereo":true})");
  const auto expected = sample_packets();
  std::size_t i = 0;
  while (auto p = reader.next_packet()) {
    ASSERT_LT(i, expected.size());
    EXPECT_EQ(*p, expected[i++]);
  }
  EXPECT_EQ(i, expected.size());
  EXPECT_FALSE(reader.next_packet());  // stays at the end
  // And the packets decode.
  Receiver rx;
  for (const auto& p : expected) EXPECT_EQ(rx.push(p), PushResult::Accepted);
}

TEST(Capture, EveryTruncationIsAClearError) {
  const std::string bytes = write_sample("truncate.trmcap");
  ASSERT_NO_THROW(read_all(bytes));
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    try {
      read_all(bytes.substr(0, n));
      ADD_FAILURE() << "no error at length " << n;
    } catch (const CaptureError& e) {
      EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << n << ": " << e.what();
    }
  }
}

TEST(Capture, CorruptionIsAClearError) {
  const std::string good = write_sample("corrupt.trmcap");
  struct Case { const char* name; std::size_t offset; char value; const char* message; };
  const std::size_t metadata_length = std::string(R"({"reduction":0.5,"stereo":true})").size();
  const std::size_t first_record = kCaptureHeaderBytes + metadata_length;
  const std::size_t end_record = good.size() - 24;
  const std::vector<Case> cases = {
      {"magic", 1, 'X', "not a TRM capture"},
      {"version", 8, 2, "format version 2"},
      {"header length", 10, 33, "header length"},
      {"packet version", 12, 9, "packet format version 9"},
      {"reserved", 14, 1, "reserved"},
      {"metadata length", 19, 0x7F, "metadata length"},
      {"metadata byte", kCaptureHeaderBytes + 3, 'Z', "metadata CRC"},
      {"record type", first_record, 'Q', "unknown record type"},
      {"record length zero", first_record + 4, 0, nullptr},
      {"record length huge", first_record + 7, 0x40, "corrupt packet record"},
      {"end count", end_record + 8, 99, "end record says"},
      {"end length", end_record + 4, 17, "corrupt end record"},
  };
  for (const Case& c : cases) {
    std::string bytes = good;
    bytes[c.offset] = c.value;
    if (std::string(c.name) == "record length zero") bytes[c.offset] = bytes[c.offset + 1] = 0;
    try {
      read_all(bytes);
      ADD_FAILURE() << c.name << ": no error";
    } catch (const CaptureError& e) {
      if (c.message) {
        EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << c.name << ": " << e.what();
      }
    }
  }
  EXPECT_THROW(read_all(good + "x"), CaptureError);  // bytes after the end record
}

TEST(Capture, MissingFileAndUnclosedWriter) {
  EXPECT_THROW(CaptureReader(out_dir() / "does_not_exist.trmcap"), CaptureError);
  const auto path = out_dir() / "unclosed.trmcap";
  std::filesystem::remove(path);
  {
    CaptureWriter writer(path, "");
    writer.write_packet(sample_packets()[0]);
  }  // destroyed without close(): nothing that looks like a capture is left
  EXPECT_FALSE(std::filesystem::exists(path));
  for (const auto& entry : std::filesystem::directory_iterator(out_dir()))
    EXPECT_EQ(entry.path().filename().string().find(".unclosed.trmcap.partial-"), std::string::npos);
  EXPECT_THROW(CaptureWriter(out_dir() / "no_such_dir" / "x.trmcap", ""), CaptureError);
}

}  // namespace
}  // namespace trm::link
