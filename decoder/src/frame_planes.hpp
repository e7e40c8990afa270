// Frame-sized planes for every decoder: fresh ones advised for huge pages, and spares of earlier views filled again
// once no caller holds them, so that a decoder in steady state allocates (and faults in) no frame-sized memory
// whatever the process's allocator does with large blocks (glibc's default maps and unmaps each one above 32 MiB).
#pragma once

#include <opencv2/core.hpp>

#include <cstddef>
#include <vector>

namespace trm::detail {

// A new frame-sized plane whose whole 2 MiB spans are advised to the kernel for transparent huge pages (Linux
// MADV_HUGEPAGE, which Debian's default "madvise" mode needs): its first touch then faults a few 2 MiB pages instead of
// one 4 KiB page at a time, which a fresh decoder's first views otherwise pay (docs/performance_history.md).
cv::Mat frame_plane(cv::Size size, int type);

// How many hold a plane's data (0 for an empty one). Read with acquire order: a caller lets a view go on a thread of
// its own (trm feed's sending thread), and its last reads of the plane must come before a reuse writes it.
int plane_owners(const cv::Mat& plane);

// At most this many spares are kept per list: beyond it a new plane takes the place of one held elsewhere (by a caller
// or by the decoder's own stores: the list forgets it, the holder's copy lives on), or else of the first free one
// (freed with it), so that a caller who keeps every view does not make the list keep them all after it lets them go.
// The largest set a decoder itself holds at once is the reference's LCD reduced view with contributed history and
// report planes: 15 planes (the eye's 8 and the view's 7).
inline constexpr std::size_t kMaxSparePlanes = 24;

// A plane of `size` and `type` from `spares` that nothing else holds, else a new frame_plane (kept in `spares`).
// Its samples are those of an earlier view: the caller writes every one.
cv::Mat reusable_plane(std::vector<cv::Mat>& spares, cv::Size size, int type);

}  // namespace trm::detail
