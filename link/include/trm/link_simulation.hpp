// The whole simulated link in two calls per run, for `trm run --link` and `trm decode --capture`:
// transmitter -> (capture) -> faults -> receiver, with bandwidth accounting per link frame.
#pragma once

#include "trm/bandwidth.hpp"
#include "trm/capture.hpp"
#include "trm/faults.hpp"
#include "trm/link.hpp"

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace trm::link {

struct LinkSimulationConfig {
  PacketizerConfig packetizer;
  LinkBudget budget;
  FaultConfig faults;                               // all zero: a perfect link
  std::optional<std::filesystem::path> capture;     // write the packet stream as sent (before faults)
  std::string capture_metadata;                     // stored in the capture header (e.g. the run's JSON config)
  ReceiverLimits limits;
};

class LinkSimulation {
 public:
  explicit LinkSimulation(LinkSimulationConfig config);  // validates everything; throws std::invalid_argument / CaptureError

  // Carries link frame t: every view (one per eye, in stream order) is packetised, recorded, sent through
  // the faults and received. Returns what the receiver hands out for this link frame, in stream order;
  // a view of which nothing arrived is absent.
  std::vector<ReceivedFrame> carry(std::int64_t t, std::span<const LinkFrame> views);

  // Closes the capture (writes its end record). Call once after the last link frame.
  void finish();

  const BandwidthMeter& meter() const { return meter_; }
  const ReceiverCounters& receiver_counters() const { return receiver_.counters(); }
  const FaultCounters& fault_counters() const { return faults_.counters(); }

 private:
  Transmitter transmitter_;
  FaultInjector faults_;
  Receiver receiver_;
  BandwidthMeter meter_;
  std::unique_ptr<CaptureWriter> capture_;
};

// Replays a capture through a receiver, frame by frame (`trm decode --capture`). Throws CaptureError
// (from the constructor or next_frame) on a truncated or corrupted file; damaged packets inside a
// well-formed capture are the receiver's business and only show up in the counters and masks.
class CaptureReplay {
 public:
  explicit CaptureReplay(const std::filesystem::path& path, ReceiverLimits limits = {});

  const std::string& metadata() const { return reader_.metadata(); }
  // The next reassembled view in (frame index, stream) order, or nullopt at the end of the capture.
  std::optional<ReceivedFrame> next_frame();
  const ReceiverCounters& counters() const { return receiver_.counters(); }

 private:
  CaptureReader reader_;
  std::vector<std::uint8_t> packet_;  // the packet being pushed, its memory reused
  Receiver receiver_;
  std::vector<ReceivedFrame> pending_;
  std::size_t next_pending_ = 0;
  bool finished_ = false;
};

}  // namespace trm::link
