#include "python/raycast_arrays.h"

#include <cmath>
#include <string>

#include "geometry/hit.h"

namespace sahara::python {

namespace {

std::string dtype_name(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

std::string shape_text(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

bool is_float_array(const py::array& a) {
    return a.dtype().kind() == 'f' && (a.itemsize() == 4 || a.itemsize() == 8);
}

void require_float(const py::array& a, const char* name) {
    if (!is_float_array(a))
        throw py::type_error(std::string(name) + ": expected a float32 or float64 array, got " +
                             dtype_name(a));
}

void require_rows_of(const py::array& a, const char* name, py::ssize_t columns, const char* rows) {
    if (a.ndim() != 2 || a.shape(1) != columns)
        throw py::value_error(std::string(name) + ": expected shape (" + rows + ", " +
                              std::to_string(columns) + "), got " + shape_text(a));
}

/// Element (row, col) of a 2-D integer array of any width and sign, as int64 (uint64 above
/// int64's range becomes negative, which the range check rejects).
int64_t integer_at(const py::array& a, py::ssize_t row, py::ssize_t col) {
    const char* p = static_cast<const char*>(a.data()) + row * a.strides(0) + col * a.strides(1);
    const bool is_signed = a.dtype().kind() == 'i';
    switch (a.itemsize()) {
        case 1:
            return is_signed ? int64_t(*reinterpret_cast<const int8_t*>(p))
                             : int64_t(*reinterpret_cast<const uint8_t*>(p));
        case 2:
            return is_signed ? int64_t(*reinterpret_cast<const int16_t*>(p))
                             : int64_t(*reinterpret_cast<const uint16_t*>(p));
        case 4:
            return is_signed ? int64_t(*reinterpret_cast<const int32_t*>(p))
                             : int64_t(*reinterpret_cast<const uint32_t*>(p));
        default:
            return is_signed ? *reinterpret_cast<const int64_t*>(p)
                             : int64_t(*reinterpret_cast<const uint64_t*>(p));
    }
}

}  // namespace

py::array as_array(const py::handle& obj, const char* name) {
    if (py::isinstance<py::array>(obj)) return py::reinterpret_borrow<py::array>(obj);
    try {
        if (py::array a = py::array::ensure(obj)) return a;  // null when numpy cannot convert it
    } catch (const py::error_already_set&) {
    }
    throw py::type_error(std::string(name) + ": expected a numpy array, got " +
                         py::str(py::type::handle_of(obj).attr("__name__")).cast<std::string>());
}

std::vector<Vec3> read_vertices(const py::array& a) {
    require_float(a, "vertices");
    require_rows_of(a, "vertices", 3, "N");
    const py::ssize_t n = a.shape(0);
    std::vector<Vec3> out(static_cast<size_t>(n));
    const char* base = static_cast<const char*>(a.data());
    const bool f64 = a.itemsize() == 8;
    for (py::ssize_t i = 0; i < n; ++i) {
        float c[3];
        for (int k = 0; k < 3; ++k) {
            const char* p = base + i * a.strides(0) + k * a.strides(1);
            c[k] = f64 ? float(*reinterpret_cast<const double*>(p)) : *reinterpret_cast<const float*>(p);
            // Checked after the conversion: a float64 beyond float's range becomes inf.
            if (!std::isfinite(c[k]))
                throw py::value_error("vertices: row " + std::to_string(i) + " is not finite in float32 (" +
                                      std::to_string(c[k]) + ")");
        }
        out[size_t(i)] = Vec3(c[0], c[1], c[2]);
    }
    return out;
}

std::vector<uint32_t> read_triangles(const py::array& a, size_t vertex_count) {
    const char kind = a.dtype().kind();
    if (kind != 'i' && kind != 'u')
        throw py::type_error("triangles: expected an integer array, got " + dtype_name(a));
    require_rows_of(a, "triangles", 3, "M");
    const py::ssize_t m = a.shape(0);
    if (size_t(m) > size_t(kPrimIndexMask) + 1)
        throw py::value_error("triangles: at most " + std::to_string(kPrimIndexMask + 1) +
                              " triangles, got " + std::to_string(m));
    std::vector<uint32_t> out(size_t(m) * 3);
    for (py::ssize_t i = 0; i < m; ++i)
        for (int k = 0; k < 3; ++k) {
            const int64_t v = integer_at(a, i, k);
            if (v < 0 || uint64_t(v) >= vertex_count)
                throw py::value_error("triangles: row " + std::to_string(i) + " refers to vertex " +
                                      std::to_string(v) + ", but vertices has " +
                                      std::to_string(vertex_count) + " rows");
            out[size_t(i) * 3 + size_t(k)] = uint32_t(v);
        }
    return out;
}

RayBatch::RayBatch(const py::handle& rays, const py::handle& tmin, const py::handle& tmax) {
    array_ = as_array(rays, "rays");
    require_float(array_, "rays");
    if (array_.ndim() < 1 || array_.shape(array_.ndim() - 1) != 6)
        throw py::value_error("rays: expected shape (..., 6) (origin, direction), got " + shape_text(array_));
    for (py::ssize_t d = 0; d + 1 < array_.ndim(); ++d) shape_.push_back(array_.shape(d));
    if (array_.ndim() != 2)
        array_ = py::array(array_.attr("reshape")(-1, 6));  // a view where numpy can make one
    data_ = static_cast<const char*>(array_.data());
    row_stride_ = array_.strides(0);
    col_stride_ = array_.strides(1);
    f64_ = array_.itemsize() == 8;
    count_ = size_t(array_.shape(0));
    tmin_ = read_limit(tmin, "tmin", 0.0f);
    tmax_ = read_limit(tmax, "tmax", kInfinity);
}

RayBatch::Limit RayBatch::read_limit(const py::handle& obj, const char* name, float fallback) const {
    Limit out;
    out.value = fallback;
    if (obj.is_none()) return out;
    if (py::isinstance<py::float_>(obj) || py::isinstance<py::int_>(obj)) {
        out.value = obj.cast<float>();
        return out;
    }
    const py::array a = as_array(obj, name);
    if (a.dtype().kind() != 'f' && a.dtype().kind() != 'i' && a.dtype().kind() != 'u')
        throw py::type_error(std::string(name) + ": expected a number or a float array, got " +
                             dtype_name(a));
    if (a.ndim() == 0) {
        out.value = a.attr("item")().cast<float>();
        return out;
    }
    if (size_t(a.size()) != count_)
        throw py::value_error(std::string(name) + ": expected one value per ray (" + std::to_string(count_) +
                              "), got shape " + shape_text(a));
    auto flat = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a.attr("reshape")(-1));
    out.values = flat.data();
    out.keep = std::move(flat);
    return out;
}

}  // namespace sahara::python
