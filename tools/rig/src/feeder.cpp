#include "rig/feeder.hpp"

#include <cmath>
#include <cstdio>
#include <thread>

namespace trm::rig {

using Clock = std::chrono::steady_clock;

std::string FeedStats::progress_line() const {
  char text[200];
  std::snprintf(text, sizeof text, "sent %lld frames, %.2f MB/s, dropped %lld, retries %lld",
                static_cast<long long>(frames_sent), megabytes_per_second(), static_cast<long long>(frames_dropped),
                static_cast<long long>(resends));
  std::string line = text;
  if (interrupted_frame && interrupted_chunk_count)
    line += ", frame " + std::to_string(*interrupted_frame) + " chunk " + std::to_string(interrupted_chunks_sent) + "/" +
            std::to_string(interrupted_chunk_count);
  return line;
}

nlohmann::json FeedStats::to_json() const {
  nlohmann::json j;
  j["frames_offered"] = frames_offered;
  j["frames_sent"] = frames_sent;
  j["frames_dropped"] = frames_dropped;
  j["resends"] = resends;
  j["packets_sent"] = packets_sent;
  j["payload_bytes_sent"] = payload_bytes_sent;
  j["wire_bytes_sent"] = wire_bytes_sent;
  j["elapsed_seconds"] = elapsed_seconds;
  j["megabytes_per_second"] = megabytes_per_second();
  j["last_frame_sent"] = last_frame_sent ? nlohmann::json(*last_frame_sent) : nlohmann::json(nullptr);
  if (interrupted_frame)
    j["interrupted"] = {{"frame", *interrupted_frame}, {"chunks_sent", interrupted_chunks_sent}, {"chunk_count", interrupted_chunk_count}};
  return j;
}

RigFeeder::RigFeeder(RigTransport& transport, FeedOptions options) : transport_(transport), options_(std::move(options)) {
  if (options_.fps < 0 || !std::isfinite(options_.fps)) throw std::invalid_argument("--fps must be >= 0");
  if (options_.preroll_frames < 0) throw std::invalid_argument("--preroll must be >= 0");
  if (options_.flow_control && !transport_.can_receive())
    throw std::invalid_argument("flow control needs a transport the rig can answer on (bulk IN endpoint or HID input reports): " +
                                transport_.description());
}

double RigFeeder::seconds_per_frame(const RigTransport& transport, const RigFrameHeader& frame) {
  const TransportRate rate = transport.nominal_rate();
  if (rate.bytes_per_second <= 0) return 0.0;
  const std::size_t packet = transport.max_packet_size();
  const std::size_t chunk_data = std::min(packet - kChunkHeaderSize, kMaxChunkData);
  const std::size_t payload = frame.payload_size();
  const std::size_t chunks = (payload + chunk_data - 1) / chunk_data;
  const std::size_t full_chunks = payload / chunk_data;
  std::size_t wire = transport.wire_bytes(kFrameStartSize) + transport.wire_bytes(kFrameEndSize) +
                     full_chunks * transport.wire_bytes(packet);
  if (chunks > full_chunks) wire += transport.wire_bytes(kChunkHeaderSize + payload - full_chunks * chunk_data);
  return static_cast<double>(wire) / rate.bytes_per_second;
}

void RigFeeder::tick(bool force) {
  const auto now = Clock::now();
  stats_.elapsed_seconds = std::chrono::duration<double>(now - started_).count();
  if (!options_.on_progress) return;
  if (force || now - last_progress_ >= options_.progress_interval) {
    last_progress_ = now;
    options_.on_progress(stats_);
  }
}

void RigFeeder::send_packet(std::span<const std::uint8_t> packet, std::size_t payload_bytes) {
  transport_.send(packet);
  ++stats_.packets_sent;
  stats_.payload_bytes_sent += payload_bytes;
  stats_.wire_bytes_sent += transport_.wire_bytes(packet.size());
  tick(false);
}

void RigFeeder::send_chunks(const EncodedFrame& frame, std::uint32_t first_sequence) {
  for (std::uint32_t sequence = first_sequence; sequence < frame.chunk_count(); ++sequence) {
    frame.chunk_packet(sequence, chunk_);
    send_packet(chunk_, chunk_.size() - kChunkHeaderSize);
    stats_.interrupted_chunks_sent = sequence + 1;
  }
  send_packet(frame.end_packet, 0);
}

void RigFeeder::await_answer(const EncodedFrame& frame) {
  int resends = 0;
  auto deadline = Clock::now() + options_.answer_timeout;
  for (;;) {
    const auto now = Clock::now();
    if (now >= deadline)
      throw RigError(RigErrorKind::Timeout, "the rig stopped answering: no READY, RESEND or ERROR for frame " +
                                                std::to_string(frame.start.frame_index) + " within " +
                                                std::to_string(options_.answer_timeout.count()) + " ms on " + transport_.description());
    const auto remaining = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - now) + std::chrono::milliseconds(1);
    const auto bytes = transport_.receive(remaining);
    if (!bytes) {
      // Some backends return at once instead of waiting; do not spin.
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    const std::optional<Answer> answer = decode_answer(*bytes);
    if (!answer || answer->frame_index != frame.start.frame_index) continue;  // stale or foreign: keep waiting
    switch (answer->kind) {
      case AnswerKind::Ready:
        return;
      case AnswerKind::Error:
        throw RigError(RigErrorKind::RigReported, "the rig reported error " + std::to_string(answer->error_code) + " (" +
                                                      describe_rig_error_code(answer->error_code) + ") for frame " +
                                                      std::to_string(answer->frame_index));
      case AnswerKind::Resend:
        if (answer->sequence >= frame.chunk_count())
          throw RigError(RigErrorKind::RigReported, "the rig asked to resend chunk " + std::to_string(answer->sequence) +
                                                        " of frame " + std::to_string(answer->frame_index) + ", which has only " +
                                                        std::to_string(frame.chunk_count()) + " chunks");
        if (++resends > options_.max_resends_per_frame)
          throw RigError(RigErrorKind::RigReported, "the rig asked for more than " + std::to_string(options_.max_resends_per_frame) +
                                                        " resends of frame " + std::to_string(answer->frame_index) +
                                                        "; the link or the rig is unreliable");
        ++stats_.resends;
        send_chunks(frame, answer->sequence);
        deadline = Clock::now() + options_.answer_timeout;
        break;
    }
  }
}

bool RigFeeder::feed(const RigFrame& frame) { return feed(frame, frame.samples); }

bool RigFeeder::feed(const RigFrameHeader& frame, std::span<const std::uint16_t> samples) {
  if (!started_clock_) {
    started_ = last_progress_ = Clock::now();
    started_clock_ = true;
  }
  const std::int64_t offered = stats_.frames_offered++;
  if (options_.fps > 0 && offered >= options_.preroll_frames) {
    // Slot k opens at t0 + k / fps, t0 when the first frame after the pre-roll came; a frame whose slot has closed
    // is dropped to keep real time.
    const std::int64_t slot = offered - options_.preroll_frames;
    const auto now = Clock::now();
    if (slot == 0) paced_from_ = now;
    const auto period = std::chrono::duration<double>(1.0 / options_.fps);
    const auto opens = paced_from_ + std::chrono::duration_cast<Clock::duration>(period * static_cast<double>(slot));
    const auto closes = paced_from_ + std::chrono::duration_cast<Clock::duration>(period * static_cast<double>(slot + 1));
    if (options_.drop_late && slot > 0 && now >= closes) {
      ++stats_.frames_dropped;
      tick(true);
      return false;
    }
    if (now < opens) std::this_thread::sleep_until(opens);
  }

  encode_frame(frame, samples, transport_.max_packet_size(), options_.flow_control, encoded_);
  const EncodedFrame& encoded = encoded_;
  stats_.interrupted_frame = frame.index;
  stats_.interrupted_chunks_sent = 0;
  stats_.interrupted_chunk_count = encoded.chunk_count();
  try {
    send_packet(encoded.start_packet, 0);
    send_chunks(encoded, 0);
    if (options_.flow_control) await_answer(encoded);
  } catch (...) {
    tick(true);
    throw;
  }
  stats_.interrupted_frame.reset();
  stats_.interrupted_chunks_sent = stats_.interrupted_chunk_count = 0;
  ++stats_.frames_sent;
  stats_.last_frame_sent = frame.index;
  tick(true);
  return true;
}

}  // namespace trm::rig
