#include "frame_planes.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace trm::detail {

cv::Mat frame_plane(cv::Size size, int type) {
  cv::Mat plane(size, type);
#if defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;
  const auto begin = reinterpret_cast<std::uintptr_t>(plane.data);
  const std::uintptr_t first = (begin + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t last = (begin + plane.total() * plane.elemSize()) & ~(kHugePage - 1);
  // Advice only: where the kernel declines it, the plane keeps its 4 KiB pages.
  if (last > first) (void)madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#endif
  return plane;
}

int plane_owners(const cv::Mat& plane) {
  return plane.u == nullptr ? 0 : std::atomic_ref<int>(plane.u->refcount).load(std::memory_order_acquire);
}

cv::Mat reusable_plane(std::vector<cv::Mat>& spares, cv::Size size, int type) {
  // Held by the list alone: no returned frame, held output or other store shares it.
  const auto free = [](const cv::Mat& spare) { return plane_owners(spare) == 1; };
  for (const cv::Mat& spare : spares) {
    if (spare.size() == size && spare.type() == type && free(spare)) return spare;
  }
  cv::Mat plane = frame_plane(size, type);
  if (spares.size() < kMaxSparePlanes) {
    spares.push_back(plane);
    return plane;
  }
  auto slot = std::find_if(spares.begin(), spares.end(), [&](const cv::Mat& spare) { return !free(spare); });
  if (slot == spares.end()) slot = spares.begin();
  *slot = plane;
  return plane;
}

}  // namespace trm::detail
