#pragma once
/// numpy arguments of sahara.RayCaster: checked (TypeError for a wrong dtype,
/// ValueError for a wrong shape or value, each naming the argument) and read in
/// place, whatever their strides, so float32 and float64 inputs need no copy.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <vector>

#include "math/ray.h"
#include "math/vec3.h"

namespace sahara::python {

namespace py = pybind11;

/// `obj` as a numpy array (lists and other array-likes converted); TypeError naming `name` otherwise.
py::array as_array(const py::handle& obj, const char* name);

/// The mesh arguments, converted to what the BVH build reads: float32 positions and
/// uint32 indices (the one copy the build needs). Checks shapes, dtypes, finite
/// coordinates and index range.
std::vector<Vec3> read_vertices(const py::array& vertices);
std::vector<uint32_t> read_triangles(const py::array& triangles, size_t vertex_count);

/// A (..., 6) float32 or float64 array of rays (origin, direction) with optional
/// per-ray or scalar tmin/tmax, read in place (safe without the GIL while the
/// arrays are alive: only raw pointers and strides are kept).
class RayBatch {
   public:
    RayBatch(const py::handle& rays, const py::handle& tmin, const py::handle& tmax);

    size_t size() const { return count_; }
    /// The leading shape of `rays` (the result arrays have it).
    const std::vector<py::ssize_t>& shape() const { return shape_; }
    Ray ray(size_t i) const {
        Ray r;
        r.origin = Vec3(coord(i, 0), coord(i, 1), coord(i, 2));
        r.dir = Vec3(coord(i, 3), coord(i, 4), coord(i, 5));
        r.tmin = tmin_.at(i);
        r.tmax = tmax_.at(i);
        return r;
    }

    /// Ray i's six floats (origin, direction) when the rays are float32 with contiguous
    /// rows, else nullptr (then ray() converts): bulk readers skip the per-value checks.
    const float* f32_row(size_t i) const {
        return f64_ || col_stride_ != py::ssize_t(sizeof(float))
                   ? nullptr
                   : reinterpret_cast<const float*>(data_ + py::ssize_t(i) * row_stride_);
    }
    float tmin(size_t i) const { return tmin_.at(i); }
    float tmax(size_t i) const { return tmax_.at(i); }
    /// Starts loading ray i's origin and direction into the cache (per-ray limits are
    /// rarer and left to the hardware).
    void prefetch(size_t i) const { __builtin_prefetch(data_ + py::ssize_t(i) * row_stride_); }

   private:
    /// A per-ray float argument: a constant or a contiguous float32 array.
    struct Limit {
        float value = 0.0f;
        const float* values = nullptr;
        py::object keep;  ///< owns `values`
        float at(size_t i) const { return values ? values[i] : value; }
    };
    Limit read_limit(const py::handle& obj, const char* name, float fallback) const;
    float coord(size_t i, int k) const {
        const char* p = data_ + py::ssize_t(i) * row_stride_ + k * col_stride_;
        return f64_ ? float(*reinterpret_cast<const double*>(p)) : *reinterpret_cast<const float*>(p);
    }

    py::array array_;  ///< keeps the rays alive
    const char* data_ = nullptr;
    py::ssize_t row_stride_ = 0, col_stride_ = 0;
    bool f64_ = false;
    size_t count_ = 0;
    std::vector<py::ssize_t> shape_;
    Limit tmin_, tmax_;
};

}  // namespace sahara::python
