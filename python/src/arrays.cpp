#include "arrays.hpp"

#include <bodyfit/error.hpp>

#include <fmt/format.h>

#include <cmath>

namespace bodyfit::python {
namespace {

template <class T>
py::array make_view(const T* data, std::size_t count, std::size_t columns, py::handle owner, bool writable) {
  std::vector<py::ssize_t> shape{py::ssize_t(count)}, strides{py::ssize_t(columns ? columns * sizeof(T) : sizeof(T))};
  if (columns) shape.push_back(py::ssize_t(columns)), strides.push_back(sizeof(T));
  static const T empty{};
  py::array a(py::dtype::of<T>(), shape, strides, data ? data : &empty, owner);
  if (!writable) py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += fmt::format("{}{}", i ? ", " : "", a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

std::string expected_shape(std::size_t rows, std::size_t columns) {
  const std::string r = rows ? std::to_string(rows) : "n";
  return columns ? fmt::format("({}, {})", r, columns) : fmt::format("({},)", r);
}

py::array checked_array(py::handle value, const std::string& what, std::size_t rows, std::size_t columns) {
  if (!py::isinstance<py::array>(value))
    throw InputError(fmt::format("{}: a numpy array of shape {} expected, got a {}", what, expected_shape(rows, columns),
                                 std::string(py::str(value.get_type().attr("__name__")))));
  auto a = py::reinterpret_borrow<py::array>(value);
  const py::ssize_t ndim = columns ? 2 : 1;
  if (a.ndim() != ndim || (columns && std::size_t(a.shape(1)) != columns) || (rows && std::size_t(a.shape(0)) != rows))
    throw InputError(fmt::format("{}: shape {}, expected {}", what, shape_of(a), expected_shape(rows, columns)));
  if (!(a.flags() & py::array::c_style))
    throw InputError(fmt::format("{}: a strided (non-contiguous) array; pass numpy.ascontiguousarray(...)", what));
  return a;
}

}  // namespace

py::array view(const double* data, std::size_t count, std::size_t columns, py::handle owner, bool writable) {
  return make_view(data, count, columns, owner, writable);
}
py::array view(const int* data, std::size_t count, std::size_t columns, py::handle owner, bool writable) {
  return make_view(data, count, columns, owner, writable);
}

py::array copy_of(const ScalarField& f) {
  py::array_t<double> a(py::ssize_t(f.size()));
  std::copy(f.begin(), f.end(), a.mutable_data());
  return a;
}

py::array copy_of(const VectorField& f) {
  py::array_t<double> a({py::ssize_t(f.size()), py::ssize_t(3)});
  if (!f.empty()) std::copy(&f[0][0], &f[0][0] + 3 * f.size(), a.mutable_data());
  return a;
}

py::array_t<double> checked_doubles(py::handle value, const std::string& what, std::size_t rows, std::size_t columns,
                                    bool finite) {
  py::array a = checked_array(value, what, rows, columns);
  if (!py::dtype::of<double>().is(a.dtype()) && a.dtype().kind() != 'f')
    throw InputError(fmt::format("{}: dtype {}, expected float64", what, std::string(py::str(a.dtype()))));
  auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  if (finite) {
    const double* p = d.data();
    const std::size_t n = std::size_t(d.size()), width = columns ? columns : 1;
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isfinite(p[i]))
        throw InputError(fmt::format("{}: {} at row {}", what, std::isnan(p[i]) ? "NaN" : "an infinite value",
                                     i / width));
  }
  return d;
}

ScalarField scalar_field(py::handle value, const std::string& what, std::size_t rows) {
  const auto a = checked_doubles(value, what, rows, 0);
  return ScalarField(a.data(), a.data() + a.size());
}

VectorField vector_field(py::handle value, const std::string& what, std::size_t rows) {
  const auto a = checked_doubles(value, what, rows, 3);
  VectorField v(std::size_t(a.shape(0)));
  if (!v.empty()) std::copy(a.data(), a.data() + a.size(), &v[0][0]);
  return v;
}

std::vector<std::int64_t> checked_integers(py::handle value, const std::string& what, std::size_t columns) {
  py::array a = checked_array(value, what, 0, columns);
  if (a.dtype().kind() != 'i' && a.dtype().kind() != 'u')
    throw InputError(fmt::format("{}: dtype {}, expected integers", what, std::string(py::str(a.dtype()))));
  auto d = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  return std::vector<std::int64_t>(d.data(), d.data() + d.size());
}

void require(bool ok, const std::string& what) {
  if (!ok) throw InputError(what);
}

std::string describe(const py::error_already_set& error) {
  try {
    py::object format = py::module_::import("traceback").attr("format_exception");
    std::string text;
    for (py::handle line : format(error.type(), error.value(), error.trace())) text += py::str(line).cast<std::string>();
    while (!text.empty() && text.back() == '\n') text.pop_back();
    return text;
  } catch (const std::exception&) {
    return error.what();
  }
}

}  // namespace bodyfit::python
