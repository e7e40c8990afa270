#include "trm/link_simulation.hpp"

namespace trm::link {

LinkSimulation::LinkSimulation(LinkSimulationConfig config)
    : transmitter_(config.packetizer), faults_(config.faults), receiver_(config.limits), meter_(config.budget) {
  if (config.capture) capture_ = std::make_unique<CaptureWriter>(*config.capture, config.capture_metadata);
}

std::vector<ReceivedFrame> LinkSimulation::carry(std::int64_t t, std::span<const LinkFrame> views) {
  std::vector<SentView> sent;
  sent.reserve(views.size());
  for (const LinkFrame& view : views) {
    if (view.meta.index != t)
      throw std::invalid_argument("link simulation: a view of frame " + std::to_string(view.meta.index) +
                                  " was passed as part of link frame " + std::to_string(t));
    sent.push_back(transmitter_.send(view));
  }
  meter_.add(t, sent);
  for (SentView& view : sent) {
    for (std::vector<std::uint8_t>& packet : view.packets) {
      if (capture_) capture_->write_packet(packet);  // as sent, before the faults
      if (faults_.apply(packet)) receiver_.push(packet);
    }
  }
  receiver_.flush();  // the link frame is over
  return receiver_.take_frames();
}

void LinkSimulation::finish() {
  if (capture_) capture_->close();
}

CaptureReplay::CaptureReplay(const std::filesystem::path& path, ReceiverLimits limits)
    : reader_(path), receiver_(limits) {}

std::optional<ReceivedFrame> CaptureReplay::next_frame() {
  while (next_pending_ == pending_.size()) {
    if (finished_) return std::nullopt;
    pending_.clear();
    next_pending_ = 0;
    if (reader_.next_packet(packet_)) {
      receiver_.push(packet_);
    } else {
      receiver_.flush();
      finished_ = true;
    }
    pending_ = receiver_.take_frames();
  }
  return std::move(pending_[next_pending_++]);
}

}  // namespace trm::link
