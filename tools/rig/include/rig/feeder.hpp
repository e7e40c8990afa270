// Streams frames into a transport at a pace, honours the rig's answers, and keeps the tally that the
// progress line and the final summary report (what was sent so far survives any error).
#pragma once

#include "rig/protocol.hpp"
#include "rig/transport.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <functional>
#include <optional>
#include <string>

namespace trm::rig {

struct FeedStats {
  std::int64_t frames_offered = 0;
  std::int64_t frames_sent = 0;      // completely delivered (and acknowledged, with flow control)
  std::int64_t frames_dropped = 0;   // skipped to keep the pace
  std::int64_t resends = 0;          // RESEND answers honoured
  std::int64_t packets_sent = 0;
  std::uint64_t payload_bytes_sent = 0;  // frame payload bytes delivered in chunks (resends included)
  std::uint64_t wire_bytes_sent = 0;     // bytes the device received, framing and padding included
  std::optional<std::int64_t> last_frame_sent;
  // The frame being sent when the feed stopped, with how far it got.
  std::optional<std::int64_t> interrupted_frame;
  std::uint32_t interrupted_chunks_sent = 0, interrupted_chunk_count = 0;
  double elapsed_seconds = 0.0;
  double megabytes_per_second() const { return elapsed_seconds > 0 ? wire_bytes_sent / elapsed_seconds / 1e6 : 0.0; }
  std::string progress_line() const;
  nlohmann::json to_json() const;
};

struct FeedOptions {
  double fps = 0.0;               // frame slots per second; 0: as fast as the transport goes
  bool drop_late = true;          // paced: skip a frame whose slot has already passed
  // Paced: frames sent as soon as they come before the pace starts with the next one, so that a source's start-up
  // (a decoder touching its frame stores for the first time) does not leave the whole run behind its slots.
  int preroll_frames = 0;
  bool flow_control = false;      // wait for READY / RESEND / ERROR after every frame
  std::chrono::milliseconds answer_timeout{2000};
  int max_resends_per_frame = 3;
  std::chrono::milliseconds progress_interval{250};
  std::function<void(const FeedStats&)> on_progress;  // called at most every progress_interval
};

class RigFeeder {
 public:
  RigFeeder(RigTransport& transport, FeedOptions options);

  // Sends one frame (or drops it when its slot has passed); returns whether it was sent. Throws
  // RigError on transport or rig failure; stats() then says how far it got.
  bool feed(const RigFrame& frame);
  // The same for a header and codes held elsewhere (a decoder's output plane, read in place).
  bool feed(const RigFrameHeader& header, std::span<const std::uint16_t> samples);
  const FeedStats& stats() const { return stats_; }

  // Time one frame of this size takes on the transport at its nominal rate (0 when unbounded).
  static double seconds_per_frame(const RigTransport& transport, const RigFrameHeader& frame);

 private:
  void send_packet(std::span<const std::uint8_t> packet, std::size_t payload_bytes);
  void send_chunks(const EncodedFrame& frame, std::uint32_t first_sequence);
  void await_answer(const EncodedFrame& frame);
  void tick(bool force);

  RigTransport& transport_;
  FeedOptions options_;
  FeedStats stats_;
  std::chrono::steady_clock::time_point started_;
  std::chrono::steady_clock::time_point last_progress_;
  // Buffers reused from frame to frame: the payload of the frame being sent and the chunk packet being sent.
  EncodedFrame encoded_;
  std::vector<std::uint8_t> chunk_;
  std::chrono::steady_clock::time_point paced_from_;  // when the first frame after the pre-roll was offered
  bool started_clock_ = false;
};

}  // namespace trm::rig
