#pragma once
// numpy arrays and the engine's fields: views without copies where the engine's memory outlives
// them, checked conversions (shape, dtype, contiguity, finiteness) with messages that name the
// argument. Shared by the bodyfit module and the python model plugin.
#include <bodyfit/mesh.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace bodyfit::python {

namespace py = pybind11;

static_assert(sizeof(Vec3) == 3 * sizeof(double), "a VectorField is n×3 doubles");

/// A view of `count` rows of `columns` values (columns 0: a 1-D array) at `data`, kept alive by
/// `owner` (a Python object holding the memory, or one whose life bounds the view's validity).
py::array view(const double* data, std::size_t count, std::size_t columns, py::handle owner, bool writable = false);
py::array view(const int* data, std::size_t count, std::size_t columns, py::handle owner, bool writable = false);
inline py::array view(const ScalarField& f, py::handle owner) { return view(f.data(), f.size(), 0, owner); }
inline py::array view(const VectorField& f, py::handle owner) {
  return view(f.empty() ? nullptr : &f[0][0], f.size(), 3, owner);
}
/// Arrays that own a copy.
py::array copy_of(const ScalarField& f);
py::array copy_of(const VectorField& f);

/// `value` as a C-contiguous float64 array of `rows` rows (`rows` 0: any) and `columns` columns
/// (0: 1-D), finite: InputError naming `what` otherwise (a non-array, the wrong shape or dtype, a
/// strided array, a NaN).
py::array_t<double> checked_doubles(py::handle value, const std::string& what, std::size_t rows, std::size_t columns,
                                    bool finite = true);
ScalarField scalar_field(py::handle value, const std::string& what, std::size_t rows);
VectorField vector_field(py::handle value, const std::string& what, std::size_t rows);
/// An integer array (any integer dtype) of `columns` columns as int64.
std::vector<std::int64_t> checked_integers(py::handle value, const std::string& what, std::size_t columns);

/// InputError(`what`) unless `ok`: the module's checks of arguments.
void require(bool ok, const std::string& what);

/// The Python exception being handled, as text: its type, message and traceback.
std::string describe(const py::error_already_set& error);

}  // namespace bodyfit::python
