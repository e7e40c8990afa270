// The line buffer of the streaming decoder (DESIGN §5): a fixed number of circular lines with a rotating index, as a
// hardware line buffer is built.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace trm::fixed_detail {

// `depth` circular lines of `samples` values; input line n lives in slot n mod depth. Reading a line that was
// overwritten (or never written) is a scheduling bug and throws.
template <typename T>
class LineRing {
 public:
  LineRing(std::string name, int depth, int samples)
      : name_(std::move(name)), samples_(samples), data_(static_cast<std::size_t>(depth) * samples), tags_(static_cast<std::size_t>(depth), -1) {}

  T* write(int line) {
    const std::size_t slot = static_cast<std::size_t>(line) % tags_.size();
    tags_[slot] = line;
    return data_.data() + slot * static_cast<std::size_t>(samples_);
  }
  const T* read(int line) const {
    const std::size_t slot = static_cast<std::size_t>(line) % tags_.size();
    if (tags_[slot] != line) {
      throw std::logic_error("line buffer '" + name_ + "': line " + std::to_string(line) + " is not held");
    }
    return data_.data() + slot * static_cast<std::size_t>(samples_);
  }

 private:
  std::string name_;
  int samples_;
  std::vector<T> data_;
  std::vector<int> tags_;
};

}  // namespace trm::fixed_detail
