#include "arrays.hpp"

#include <stdexcept>

namespace trm::python {

namespace {

const char* element_name(Element element) {
  switch (element) {
    case Element::Float64: return "float64";
    case Element::Uint16: return "uint16";
    case Element::Uint8: return "uint8";
  }
  return "?";
}

py::dtype element_dtype(Element element) {
  switch (element) {
    case Element::Float64: return py::dtype::of<double>();
    case Element::Uint16: return py::dtype::of<std::uint16_t>();
    case Element::Uint8: return py::dtype::of<std::uint8_t>();
  }
  throw std::logic_error("unknown element type");
}

int cv_depth(Element element) {
  switch (element) {
    case Element::Float64: return CV_64F;
    case Element::Uint16: return CV_16U;
    case Element::Uint8: return CV_8U;
  }
  throw std::logic_error("unknown element type");
}

std::string shape_text(const py::array& a) {
  std::string text = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) text += (i ? ", " : "") + std::to_string(a.shape(i));
  return text + (a.ndim() == 1 ? ",)" : ")");
}

}  // namespace

cv::Mat borrow_image(const py::handle& array, Element element, int channels, const std::string& what, py::object& keep) {
  if (!py::isinstance<py::array>(array)) {
    throw std::invalid_argument(what + ": expected a numpy array, got " + std::string(py::str(array.get_type())));
  }
  py::array a = py::reinterpret_borrow<py::array>(array);
  const std::string expected_shape = channels == 3 ? "(height, width, 3)" : "(height, width)";
  if (!a.dtype().is(element_dtype(element))) {
    throw std::invalid_argument(what + ": expected dtype " + element_name(element) + ", got " +
                                std::string(py::str(a.dtype())) + " (convert with .astype(np." +
                                element_name(element) + ") if that is what you mean)");
  }
  const bool shape_ok = channels == 3 ? a.ndim() == 3 && a.shape(2) == 3 : a.ndim() == 2;
  if (!shape_ok || a.size() == 0) {
    throw std::invalid_argument(what + ": expected a non-empty array of shape " + expected_shape + ", got shape " +
                                shape_text(a));
  }
  if (a.shape(0) > 65535 || a.shape(1) > 65535) {
    throw std::invalid_argument(what + ": " + shape_text(a) + " is larger than 65535 pixels per side");
  }
  if (!(a.flags() & py::array::c_style)) {
    a = py::array::ensure(a, py::array::c_style);  // the one copy: a strided view into a contiguous buffer
  }
  keep = a;
  return cv::Mat(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)), CV_MAKETYPE(cv_depth(element), channels),
                 const_cast<void*>(a.data()));
}

cv::Mat borrow_codes_image(const py::handle& array, const std::string& what, py::object& keep) {
  if (py::isinstance<py::array>(array) &&
      py::reinterpret_borrow<py::array>(array).dtype().is(py::dtype::of<std::uint8_t>())) {
    return borrow_image(array, Element::Uint8, 3, what, keep);
  }
  if (py::isinstance<py::array>(array) &&
      !py::reinterpret_borrow<py::array>(array).dtype().is(py::dtype::of<std::uint16_t>())) {
    throw std::invalid_argument(what + ": expected dtype uint8 or uint16, got " +
                                std::string(py::str(py::reinterpret_borrow<py::array>(array).dtype())));
  }
  return borrow_image(array, Element::Uint16, 3, what, keep);
}

py::array share_image(const cv::Mat& image) {
  py::dtype dtype;
  switch (image.depth()) {
    case CV_64F: dtype = py::dtype::of<double>(); break;
    case CV_16U: dtype = py::dtype::of<std::uint16_t>(); break;
    case CV_8U: dtype = py::dtype::of<std::uint8_t>(); break;
    default: throw std::logic_error("share_image: unsupported matrix depth " + std::to_string(image.depth()));
  }
  if (image.empty()) return py::array(dtype, std::vector<py::ssize_t>{0, 0, 3});
  auto* held = new cv::Mat(image);  // a reference: the buffer lives as long as the array
  py::capsule owner(held, [](void* p) { delete static_cast<cv::Mat*>(p); });
  const auto element = static_cast<py::ssize_t>(image.elemSize1());
  std::vector<py::ssize_t> shape{image.rows, image.cols};
  std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(image.step[0]), static_cast<py::ssize_t>(image.elemSize())};
  if (image.channels() > 1) {
    shape.push_back(image.channels());
    strides.push_back(element);
  }
  py::array out(dtype, shape, strides, held->data, owner);
  // numpy's flags directly: the attribute route (a.flags.writeable = False) costs several microseconds per array
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

}  // namespace trm::python
