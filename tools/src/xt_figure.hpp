// The paper's Fig. 12 for one display method: a moving target's scan line over time as the panel emits it
// (physical x–t image), as it lands on a pursuing retina (retinal x–t image), the time-integrated percept, and the
// Fourier view of the physical image with the window of visibility of the pursuing eye.
#pragma once

#include "trm/panel_light.hpp"
#include "trm/retina.hpp"

#include <opencv2/core.hpp>

#include <string>

namespace trm::cli {

struct XtFigureInput {
  std::string title;            // written above the panels
  cv::Mat levels;               // K×N CV_64FC1: the steady luminance each frame drives on the scan line
  PanelLight light;
  Viewer viewer;
  Gaze gaze;
  RetinaOptions retina;         // sub-steps and the scan line's row (its scan-out delay)
  int window_begin = 0;         // the columns shown: [window_begin, window_begin + window_width) of the line
  int window_width = 192;
};

// An RGB CV_8UC3 image, four panels left to right. Time runs down each x–t panel (K·S rows of the sub-frame
// samples), x across. The Fourier panel is log |F| of the physical panel, zero frequency at the centre, spatial
// frequency across and temporal frequency down, tinted where the stCSF of the eye (retinal velocity −v_eye in the
// screen's frame; for a gaze on a path, its mean velocity) is at least 1: energy outside the tint is invisible,
// aliases inside it are judder or flicker.
// Throws std::invalid_argument naming what is wrong (empty levels, a window outside the line).
cv::Mat xt_figure(const XtFigureInput& input);

}  // namespace trm::cli
