// Transfer functions and link quantisation (DESIGN §3), in double precision.
#pragma once

#include "trm/frame.hpp"

namespace trm {

// Encoded value -> linear light, and back. Inputs outside [0, 1] are clamped first.
double to_linear(double encoded, Transfer transfer);
double to_encoded(double linear, Transfer transfer);
cv::Mat to_linear(const cv::Mat& encoded, Transfer transfer);   // CV_64F, any channel count
cv::Mat to_encoded(const cv::Mat& linear, Transfer transfer);

// q = floor(x * (2^bits - 1) + 0.5) after clamping x to [0, 1]; returns CV_16U with the same channels.
cv::Mat quantise(const cv::Mat& values, int bits);
// code / (2^bits - 1), CV_64F.
cv::Mat dequantise(const cv::Mat& codes, int bits);

// Rec. 709 luma on linear RGB: Y = 0.2126 R + 0.7152 G + 0.0722 B (CV_64FC3 -> CV_64FC1).
cv::Mat luma(const cv::Mat& linear_rgb);

}  // namespace trm
