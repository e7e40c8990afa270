// Mean Temporal Color Difference (Kim et al., "head movement based temporal antialiasing", Eq. 6): how much the
// colour of each pixel changes from one frame to the next, averaged over the image and the sequence.
//
//   MTCD(I, t) = 1 / (n m (t − 1)) · Σ_{k=1}^{t−1} Σ_{j=0}^{m−1} Σ_{i=0}^{n−1} d_ijk
//   d_ijk      = sqrt((r_ij(k−1) − r_ijk)² + (g_ij(k−1) − g_ijk)² + (b_ij(k−1) − b_ijk)²)
//
// I is the sequence of t frames (k = 0 … t−1), n × m their width × height. 0 is the ideal (no temporal change).
#pragma once

#include <opencv2/core.hpp>

#include <vector>

namespace trm {

// Eq. 6 over `frames` (t >= 2), in the frames' own units (e.g. 0–255 for 8-bit frames: the paper fixes none).
// Every frame has one size and type, 3 channels (r, g, b in any order: the distance does not depend on it) or 1
// channel (then d_ijk = |I_ij(k−1) − I_ijk|, Eq. 6 for a grey sequence), any depth, finite values. Throws
// std::invalid_argument naming `frames` (fewer than 2, or frame k empty, of another size or type, of 2 or 4
// channels, or with a non-finite value).
double mtcd(const std::vector<cv::Mat>& frames);

}  // namespace trm
