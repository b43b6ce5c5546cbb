#pragma once
// The one place where Python values become core values, and results become Python values, for
// every binding. Each reader takes `where`, the path of the value in the caller's arguments
// (profile['min_segment'], wires[2]['points'], steps[1][0]), and throws InputError (ValueError in
// Python) naming it: "profile['min_segment']: expected a number, got str". Dicts are read against
// a table of fields; an unknown key is named together with the keys that exist.
//
// Only conversion and type/shape checks live here (plus finiteness, which no option of the core
// ever wants otherwise); ranges and meaning are the core's. Call with the GIL held.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "wiresculpt/error.hpp"

namespace wiresculpt::python {

namespace py = pybind11;

/// The Python type of `v` as messages show it: "str", "list", "numpy.ndarray", "None".
inline std::string type_name(py::handle v) { return v.is_none() ? "None" : Py_TYPE(v.ptr())->tp_name; }

/// repr(v), cut to a message's length.
inline std::string shown(py::handle v) {
  std::string s = py::repr(v);
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

[[noreturn]] inline void wrong(const std::string& where, const std::string& expected, const std::string& got) {
  throw InputError(where + ": expected " + expected + ", got " + got);
}

inline std::string key_path(const std::string& where, const std::string& key) { return where + "['" + key + "']"; }
inline std::string index_path(const std::string& where, std::size_t i) { return where + "[" + std::to_string(i) + "]"; }

// --- scalars --------------------------------------------------------------------------------------

/// A finite float from an int, a float or a numpy scalar (never a bool or a string).
inline double to_number(py::handle v, const std::string& where) {
  PyObject* o = v.ptr();
  if (PyBool_Check(o) || PyComplex_Check(o) || !PyNumber_Check(o)) wrong(where, "a number", type_name(v));
  const double x = PyFloat_AsDouble(o);
  if (x == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    wrong(where, "a finite number", type_name(v) + " " + shown(v));
  }
  if (!std::isfinite(x)) wrong(where, "a finite number", shown(v));
  return x;
}

/// An integer of type T from an int or a numpy integer (never a bool or a float), in T's range.
template <class T = int>
T to_integer(py::handle v, const std::string& where) {
  PyObject* o = v.ptr();
  if (PyBool_Check(o) || !PyIndex_Check(o)) wrong(where, "an integer", type_name(v));
  const py::object i = py::reinterpret_steal<py::object>(PyNumber_Index(o));
  if (!i) {
    PyErr_Clear();
    wrong(where, "an integer", type_name(v));
  }
  constexpr long long lo = static_cast<long long>(std::numeric_limits<T>::min());
  constexpr long long hi = static_cast<unsigned long long>(std::numeric_limits<T>::max()) >
                                       static_cast<unsigned long long>(std::numeric_limits<long long>::max())
                               ? std::numeric_limits<long long>::max()
                               : static_cast<long long>(std::numeric_limits<T>::max());
  int overflow = 0;
  const long long x = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
  if (overflow || x < lo || x > hi)
    wrong(where, "an integer from " + std::to_string(lo) + " to " + std::to_string(hi), shown(v));
  return static_cast<T>(x);
}

/// True or False (a Python or numpy bool; never 0 / 1 or a string).
inline bool to_bool(py::handle v, const std::string& where) {
  if (PyBool_Check(v.ptr())) return v.ptr() == Py_True;
  if (type_name(v) == "numpy.bool_") return PyObject_IsTrue(v.ptr()) == 1;
  wrong(where, "True or False", type_name(v));
}

inline std::string to_text(py::handle v, const std::string& where) {
  if (!PyUnicode_Check(v.ptr())) wrong(where, "a string", type_name(v));
  Py_ssize_t size = 0;
  const char* utf8 = PyUnicode_AsUTF8AndSize(v.ptr(), &size);
  if (!utf8) {  // lone surrogates
    PyErr_Clear();
    wrong(where, "a string of Unicode characters", "a str with a lone surrogate");
  }
  return {utf8, static_cast<std::size_t>(size)};
}

// --- containers -----------------------------------------------------------------------------------

/// Calls f(item, path) for every item of a list, tuple or 1-D array (never a string or a dict).
template <class F>
void each_item(py::handle v, const std::string& where, F&& f) {
  PyObject* o = v.ptr();
  if (PyUnicode_Check(o) || PyBytes_Check(o) || PyDict_Check(o) || !PySequence_Check(o))
    wrong(where, "a list", type_name(v));
  const auto s = py::reinterpret_borrow<py::sequence>(v);
  const std::size_t n = s.size();
  for (std::size_t i = 0; i < n; ++i) f(s[i], index_path(where, i));
}

template <class T = int>
std::vector<T> to_integers(py::handle v, const std::string& where) {
  std::vector<T> out;
  each_item(v, where, [&](py::handle item, const std::string& at) { out.push_back(to_integer<T>(item, at)); });
  return out;
}

/// A list of lists of integers (assembly steps).
inline std::vector<std::vector<int>> to_integer_lists(py::handle v, const std::string& where) {
  std::vector<std::vector<int>> out;
  each_item(v, where, [&](py::handle item, const std::string& at) { out.push_back(to_integers<int>(item, at)); });
  return out;
}

/// Exactly N numbers (a list, tuple or array).
template <int N>
Eigen::Matrix<double, N, 1> to_vector(py::handle v, const std::string& where) {
  PyObject* o = v.ptr();
  if (PyUnicode_Check(o) || PyBytes_Check(o) || PyDict_Check(o) || !PySequence_Check(o))
    wrong(where, std::to_string(N) + " numbers", type_name(v));
  const auto s = py::reinterpret_borrow<py::sequence>(v);
  if (s.size() != static_cast<std::size_t>(N))
    wrong(where, std::to_string(N) + " numbers", type_name(v) + " of " + std::to_string(s.size()));
  Eigen::Matrix<double, N, 1> out;
  for (int k = 0; k < N; ++k) out[k] = to_number(s[static_cast<std::size_t>(k)], index_path(where, static_cast<std::size_t>(k)));
  return out;
}

/// An (n, K) array of numbers (a numpy array or nested lists) as n points. Values are not
/// checked for finiteness: the core names the point at fault.
template <int K>
std::vector<Eigen::Matrix<double, K, 1>> to_points(py::handle v, const std::string& where) {
  const std::string expected = "an (n, " + std::to_string(K) + ") array of numbers";
  const py::array any = py::array::ensure(v);
  if (!any) wrong(where, expected, type_name(v));
  const char kind = any.dtype().kind();
  if (kind != 'i' && kind != 'u' && kind != 'f') wrong(where, expected, "an array of " + std::string(py::str(any.dtype())));
  if (any.ndim() != 2 || any.shape(1) != K) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < any.ndim(); ++d) {
      if (d) shape += ", ";
      shape += std::to_string(any.shape(d));
    }
    wrong(where, expected, "shape " + shape + (any.ndim() == 1 ? ",)" : ")"));
  }
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(any);
  if (!a) wrong(where, expected, type_name(v));
  const auto r = a.template unchecked<2>();
  std::vector<Eigen::Matrix<double, K, 1>> out(static_cast<std::size_t>(r.shape(0)));
  for (py::ssize_t i = 0; i < r.shape(0); ++i)
    for (int k = 0; k < K; ++k) out[static_cast<std::size_t>(i)][k] = r(i, k);
  return out;
}

// --- dicts ----------------------------------------------------------------------------------------

/// One key a dict may hold and how its value is read (`at` is the value's path).
struct Field {
  std::string key;
  std::function<void(py::handle value, const std::string& at)> read;
};

/// Reads every key of the dict `d` with the field of that name. A value that is not a dict, a
/// key that is not a string or a key no field reads is an InputError naming it. Returns the keys
/// read, in the dict's order.
inline std::vector<std::string> read_fields(py::handle d, const std::string& where, const std::vector<Field>& fields) {
  if (!PyDict_Check(d.ptr())) wrong(where, "a dict", type_name(d));
  std::vector<std::string> seen;
  for (const auto& item : py::reinterpret_borrow<py::dict>(d)) {
    if (!PyUnicode_Check(item.first.ptr()))
      throw InputError(where + ": keys must be strings, got " + type_name(item.first) + " " + shown(item.first));
    const std::string key = to_text(item.first, where + " key");
    const auto it = std::find_if(fields.begin(), fields.end(), [&](const Field& f) { return f.key == key; });
    if (it == fields.end()) {
      std::string known;
      for (const Field& f : fields) known += (known.empty() ? "" : ", ") + f.key;
      throw InputError(where + ": unknown key '" + key + "' (expected " + known + ")");
    }
    it->read(item.second, key_path(where, key));
    seen.push_back(key);
  }
  return seen;
}

/// InputError naming the first of `keys` that read_fields did not see.
inline void require_keys(const std::vector<std::string>& seen, const std::string& where,
                         std::initializer_list<const char*> keys) {
  for (const char* key : keys)
    if (std::find(seen.begin(), seen.end(), key) == seen.end()) throw InputError(where + ": the key '" + key + "' is missing");
}

/// Field makers for the common cases: the value read into `out`.
namespace field {

inline Field number(std::string key, double& out) {
  return {std::move(key), [&out](py::handle v, const std::string& at) { out = to_number(v, at); }};
}

template <class T>
Field integer(std::string key, T& out) {
  return {std::move(key), [&out](py::handle v, const std::string& at) { out = to_integer<T>(v, at); }};
}

inline Field boolean(std::string key, bool& out) {
  return {std::move(key), [&out](py::handle v, const std::string& at) { out = to_bool(v, at); }};
}

inline Field text(std::string key, std::string& out) {
  return {std::move(key), [&out](py::handle v, const std::string& at) { out = to_text(v, at); }};
}

/// One of the named strings, each standing for a value of E.
template <class E>
Field choice(std::string key, E& out, std::vector<std::pair<std::string, E>> options) {
  return {std::move(key), [&out, options = std::move(options)](py::handle v, const std::string& at) {
            const std::string s = to_text(v, at);
            std::string names;
            for (const auto& [name, value] : options) {
              if (name == s) {
                out = value;
                return;
              }
              names += (names.empty() ? "'" : ", '") + name + "'";
            }
            wrong(at, "one of " + names, "'" + s + "'");
          }};
}

}  // namespace field

// --- results --------------------------------------------------------------------------------------

/// A dict of the given key, value pairs (`make_dict("a", 1, "b", x)`): each value is cast as
/// pybind11 casts it and stored with PyDict_SetItemString. py::dict(py::arg("a") = 1, ...) builds
/// the same dict through a kwargs dict, making and looking up every key string twice (callgrind,
/// the Car's six target-shape results: 1.7 M instructions in to_dict that way, 0.4 M this way).
inline void put_items(py::dict&) {}
template <class V, class... Rest>
void put_items(py::dict& d, const char* key, V&& value, Rest&&... rest) {
  py::object v;
  if constexpr (std::is_base_of_v<py::handle, std::decay_t<V>>)
    v = py::reinterpret_borrow<py::object>(value);
  else
    v = py::cast(std::forward<V>(value));
  if (!v) {  // a failed conversion (out of memory) or a null handle: never a NULL into the dict
    if (PyErr_Occurred()) throw py::error_already_set();
    throw py::cast_error(std::string("make_dict: no value for '") + key + "'");
  }
  if (PyDict_SetItemString(d.ptr(), key, v.ptr()) != 0) throw py::error_already_set();
  put_items(d, std::forward<Rest>(rest)...);
}
template <class... Items>
py::dict make_dict(Items&&... items) {
  static_assert(sizeof...(Items) % 2 == 0, "make_dict takes key, value pairs");
  py::dict d;
  put_items(d, std::forward<Items>(items)...);
  return d;
}

/// Points as an (n, K) float64 array.
template <class Point>
py::array_t<double> to_array(const std::vector<Point>& points) {
  constexpr int K = Point::RowsAtCompileTime;
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), static_cast<py::ssize_t>(K)});
  auto w = out.template mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < w.shape(0); ++i)
    for (py::ssize_t k = 0; k < K; ++k) w(i, k) = points[static_cast<std::size_t>(i)][static_cast<Eigen::Index>(k)];
  return out;
}

/// A fixed-size vector as a list of floats (made at its size and each set in its place, without
/// append's calls and resizing: a solve converts thousands of points).
template <class Derived>
py::list to_list(const Eigen::MatrixBase<Derived>& v) {
  py::list out(static_cast<std::size_t>(v.size()));
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    PyObject* x = PyFloat_FromDouble(v[k]);
    if (!x) throw py::error_already_set();
    PyList_SET_ITEM(out.ptr(), k, x);
  }
  return out;
}

/// Points as a list of lists of floats (the design document's polylines).
template <class Point>
py::list to_lists(const std::vector<Point>& points) {
  py::list out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    PyList_SET_ITEM(out.ptr(), static_cast<Py_ssize_t>(i), to_list(points[i]).release().ptr());
  return out;
}

}  // namespace wiresculpt::python
