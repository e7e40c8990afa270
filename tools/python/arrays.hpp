// numpy arrays <-> cv::Mat for the Python module. Images are HxWx3 (or HxW for one channel) in RGB order, as every
// trm image is.
//
// Into C++: an array of exactly the expected dtype is wrapped without a copy when it is C-contiguous (a strided
// view, e.g. a[::2], is copied once into a contiguous buffer); the wrapping cv::Mat borrows the array's memory, so
// it is used only during the call. A wrong dtype or shape is a ValueError naming the argument, never converted.
// Out of C++: the returned array shares the cv::Mat's buffer (no copy) and keeps it alive through a capsule holding a
// reference; it is read-only because the decoders keep and reuse their planes (np.array(a) for a writable copy).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <opencv2/core.hpp>

#include <string>

namespace trm::python {

namespace py = pybind11;

// The numpy dtype an image argument must have.
enum class Element { Float64, Uint16, Uint8 };

// An image argument as a cv::Mat: `channels` 3 means HxWx3, 1 means HxW. The result borrows `array`'s memory (or the
// copy's, held in `keep`); keep `keep` alive while the cv::Mat is used. Throws std::invalid_argument naming `what`.
cv::Mat borrow_image(const py::handle& array, Element element, int channels, const std::string& what, py::object& keep);

// Like borrow_image, for an HxWx3 image of either uint8 or uint16 codes (write_png, mtcd).
cv::Mat borrow_codes_image(const py::handle& array, const std::string& what, py::object& keep);

// The cv::Mat as a read-only numpy array sharing its buffer (CV_8U, CV_16U, CV_64F; 1 or 3 channels).
py::array share_image(const cv::Mat& image);

}  // namespace trm::python
