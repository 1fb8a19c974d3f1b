#include "python/raycaster.h"

#include <pybind11/numpy.h>
#include <pybind11/stl/filesystem.h>

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include "io/model_loader.h"
#include "python/bindings.h"
#include "python/raycast_arrays.h"
#include "python/raycast_mesh.h"

namespace sahara::python {

namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(float), "vertices are exposed as an (N, 3) float32 view");

/// A new array of the batch's leading shape, plus `extra` trailing dimensions.
template <class T>
py::array_t<T> result_array(const RayBatch& rays, std::initializer_list<py::ssize_t> extra = {}) {
    std::vector<py::ssize_t> shape = rays.shape();
    shape.insert(shape.end(), extra.begin(), extra.end());
    return py::array_t<T>(shape);
}

/// A read-only (rows, 3) view of `data` that keeps `owner` alive.
template <class T>
py::array read_only_view(const T* data, size_t rows, const py::object& owner) {
    py::array_t<T> a({py::ssize_t(rows), py::ssize_t(3)}, data, owner);
    a.attr("setflags")(py::arg("write") = false);
    return a;
}

/// How long one slice of a cast should take: between slices the calling thread runs
/// Python's signal handlers, so Ctrl-C waits about this long. Each slice's size follows
/// the rays per second of the one before (rays cost from nanoseconds to milliseconds,
/// depending on the mesh), growing at most fourfold per slice. The first takes a quarter
/// of that time at the rate of the caster's last batch (small on its first batch):
/// batches differ, and one with rays a hundred times slower than the last then still
/// checks for Ctrl-C within seconds.
constexpr double kSliceSeconds = 0.1;
constexpr double kFirstSliceFraction = 0.25;
constexpr size_t kFirstSliceRays = 4096;
constexpr size_t kMinSliceRays = 256;

/// A `threads` argument: None (the caster's own setting, or all for the constructor) or 0
/// for all threads, otherwise the count.
int threads_arg(const py::object& threads, int fallback) {
    const auto n = int_arg(threads, "threads", 0, 1 << 16);
    return n ? int(*n) : fallback;
}

/// OpenMP's thread count for the parallel regions this thread starts, for a scope.
class ThreadsInScope {
   public:
    explicit ThreadsInScope(int threads) : saved_(omp_get_max_threads()) {
        if (threads > 0) omp_set_num_threads(threads);
    }
    ~ThreadsInScope() { omp_set_num_threads(saved_); }
    ThreadsInScope(const ThreadsInScope&) = delete;
    ThreadsInScope& operator=(const ThreadsInScope&) = delete;

   private:
    int saved_;
};

/// Runs `cast(slice)` over the batch slice by slice with the GIL released; between slices
/// this thread runs Python's signal handlers, so Ctrl-C (or any exception a handler
/// raises) stops the cast after the current slice. Every slice is a parallel region
/// whose end all threads wait for (a thread the system holds back stalls the others),
/// so a long cast should take few: the first slice is sized by the rate per thread of
/// the caster's last batch (CastMesh::slice_rate), which this cast then updates with the
/// rate of its longest slice.
template <class Cast>
void cast_interruptibly(const CastMesh& mesh, size_t count, int threads, const Cast& cast) {
    using Clock = std::chrono::steady_clock;
    const int team = threads > 0 ? threads : omp_get_max_threads();
    size_t step =
        std::max(kFirstSliceRays, size_t(mesh.slice_rate() * team * kSliceSeconds * kFirstSliceFraction));
    double longest = 0.0, rate_of_longest = 0.0;
    for (size_t first = 0; first < count;) {
        const RaySlice slice{first, std::min(count, first + step), threads};
        const auto start = Clock::now();
        {
            py::gil_scoped_release release;
            cast(slice);
        }
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        const double rate = double(slice.last - first) / std::max(seconds, 1e-6);
        if (seconds > longest) longest = seconds, rate_of_longest = rate;
        step = std::clamp(size_t(rate * kSliceSeconds), kMinSliceRays, 4 * step);
        first = slice.last;
    }
    if (longest > 0.0) mesh.set_slice_rate(rate_of_longest / team);
}

TraceOrder trace_order(const CastMesh& mesh, const RayBatch& rays, int threads) {
    py::gil_scoped_release release;
    return mesh.trace_order(rays, threads);
}

std::unique_ptr<CastMesh> mesh_from_arrays(const py::handle& vertices, const py::handle& triangles,
                                           const py::object& threads) {
    const int n = threads_arg(threads, 0);
    std::vector<Vec3> positions = read_vertices(as_array(vertices, "vertices"));
    std::vector<uint32_t> indices = read_triangles(as_array(triangles, "triangles"), positions.size());
    py::gil_scoped_release release;
    const ThreadsInScope build_threads(n);
    auto mesh = std::make_unique<CastMesh>(std::move(positions), std::move(indices));
    mesh->set_threads(n);
    return mesh;
}

/// The meshes of a model file merged in file order (triangle ids count across meshes).
std::unique_ptr<CastMesh> mesh_from_file(const std::filesystem::path& path, const py::object& threads) {
    const int n = threads_arg(threads, 0);
    py::gil_scoped_release release;
    const ThreadsInScope build_threads(n);
    LoadedModel model = load_model(path);
    bake_instances(model);  // triangle ids count every drawn triangle
    std::vector<Vec3> positions;
    std::vector<uint32_t> indices;
    for (const TriangleMesh& m : model.meshes) {
        const auto base = uint32_t(positions.size());
        positions.insert(positions.end(), m.positions.begin(), m.positions.end());
        for (uint32_t i : m.indices) indices.push_back(base + i);
    }
    auto mesh = std::make_unique<CastMesh>(std::move(positions), std::move(indices));
    mesh->set_threads(n);
    return mesh;
}

py::dict cast_rays(const CastMesh& mesh, const py::handle& rays_in, const py::handle& tmin,
                   const py::handle& tmax, const py::object& threads) {
    const int n = threads_arg(threads, mesh.threads());
    const RayBatch rays(rays_in, tmin, tmax);
    auto t = result_array<float>(rays);
    auto prim = result_array<int64_t>(rays);
    auto uv = result_array<float>(rays, {2});
    auto normal = result_array<float>(rays, {3});
    const NearestHits out{t.mutable_data(), prim.mutable_data(), uv.mutable_data(), normal.mutable_data()};
    TraceOrder order = trace_order(mesh, rays, n);
    cast_interruptibly(mesh, rays.size(), n, [&](RaySlice slice) { mesh.nearest(order, slice, out); });
    {
        py::gil_scoped_release release;
        mesh.write_sorted_hits(order, n, out);
        mesh.recycle(std::move(order));
    }
    py::dict d;
    d["t_hit"] = t;
    d["primitive_ids"] = prim;
    d["primitive_uvs"] = uv;
    d["normals"] = normal;
    return d;
}

py::array_t<bool> occluded(const CastMesh& mesh, const py::handle& rays_in, const py::handle& tmin,
                           const py::handle& tmax, const py::object& threads) {
    const int n = threads_arg(threads, mesh.threads());
    const RayBatch rays(rays_in, tmin, tmax);
    auto out = result_array<bool>(rays);
    bool* p = out.mutable_data();
    TraceOrder order = trace_order(mesh, rays, n);
    cast_interruptibly(mesh, rays.size(), n, [&](RaySlice slice) { mesh.occluded(order, slice, p); });
    mesh.recycle(std::move(order));
    return out;
}

py::array_t<int32_t> count_intersections(const CastMesh& mesh, const py::handle& rays_in,
                                         const py::handle& tmin, const py::handle& tmax) {
    const RayBatch rays(rays_in, tmin, tmax);
    auto out = result_array<int32_t>(rays);
    int32_t* p = out.mutable_data();
    py::gil_scoped_release release;
    mesh.count_crossings(rays, p);
    return out;
}

py::dict intersect_all(const CastMesh& mesh, const py::handle& rays_in, const py::handle& tmin,
                       const py::handle& tmax) {
    const RayBatch rays(rays_in, tmin, tmax);
    Crossings found;
    {
        py::gil_scoped_release release;
        found = mesh.crossings(rays);
    }
    const auto n = py::ssize_t(found.total());
    py::array_t<int64_t> ray(n), prim(n);
    py::array_t<float> t(n), uv({n, py::ssize_t(2)});
    {
        int64_t *pr = ray.mutable_data(), *pp = prim.mutable_data();
        float *pt = t.mutable_data(), *puv = uv.mutable_data();
        py::gil_scoped_release release;
        found.write(pr, pp, pt, puv);
        found = Crossings{};
    }
    py::dict d;
    d["ray_ids"] = ray;
    d["primitive_ids"] = prim;
    d["t"] = t;
    d["primitive_uvs"] = uv;
    return d;
}

}  // namespace

void bind_raycaster(py::module_& m) {
    py::class_<CastMesh>(m, "RayCaster", R"doc(
Rays cast into one triangle mesh through sahara's watertight 8-wide BVH.

RayCaster(vertices, triangles, *, threads=None): vertices an (N, 3) float32 or float64 array,
triangles an (M, 3) integer array of vertex indices (counter-clockwise is the
front). The BVH is built once, in float32; the caster keeps a float32/uint32
copy of the mesh for normals and for the `vertices`/`triangles` views.

Every query takes rays as a (..., 6) float32/float64 array (origin, direction;
t is measured in units of |direction|) and optional tmin/tmax (a number or one
value per ray; defaults 0 and inf; hits need tmin < t < tmax). Queries run
with the GIL released on `threads` OpenMP threads (None or 0: all; the BVH build
too); cast_rays and occluded take their own threads= and stop with
KeyboardInterrupt on Ctrl-C. Large incoherent batches are traced in a sorted
order whose buffers (72 bytes per ray) the caster keeps for its next batch, up to
128 MB.)doc")
        .def(py::init(&mesh_from_arrays), py::arg("vertices"), py::arg("triangles"), py::kw_only(),
             py::arg("threads") = py::none(),
             "Builds the BVH over vertices (N, 3) and triangles (M, 3) once; threads (keyword only) is "
             "the default thread count of the queries.")
        .def_static("from_file", &mesh_from_file, py::arg("path"), py::kw_only(),
                    py::arg("threads") = py::none(),
                    "A caster over every mesh of an OBJ or glTF file, merged; triangle ids count in the "
                    "order the loader reads them (the `triangles` property lists them).")
        .def("cast_rays", &cast_rays, py::arg("rays"), py::arg("tmin") = py::none(),
             py::arg("tmax") = py::none(), py::kw_only(), py::arg("threads") = py::none(),
             "Nearest hits: a dict of t_hit (float32, inf on a miss), primitive_ids (int64, -1 on a miss), "
             "primitive_uvs (float32 (..., 2): barycentric weights of the triangle's 2nd and 3rd vertex) and "
             "normals (float32 (..., 3): the unit geometric normal, counter-clockwise front, not flipped "
             "towards the ray; 0 on a miss).")
        .def("occluded", &occluded, py::arg("rays"), py::arg("tmin") = py::none(),
             py::arg("tmax") = py::none(), py::kw_only(), py::arg("threads") = py::none(),
             "Whether anything lies on each ray with tmin < t < tmax (bool array).")
        .def("intersect_all", &intersect_all, py::arg("rays"), py::arg("tmin") = py::none(),
             py::arg("tmax") = py::none(),
             "Every crossing along every ray as flat arrays ray_ids (int64, index into the flattened rays), "
             "primitive_ids (int64), t (float32) and primitive_uvs, sorted by ray then t. A ray through a "
             "shared edge or vertex crosses there once; one that only touches the surface there, 0 or 2 "
             "times, so the count's parity tells inside from outside on closed meshes.")
        .def("count_intersections", &count_intersections, py::arg("rays"), py::arg("tmin") = py::none(),
             py::arg("tmax") = py::none(), "The number of crossings intersect_all finds per ray (int32).")
        .def_property_readonly(
            "vertices",
            [](const py::object& self) {
                const auto& mesh = self.cast<const CastMesh&>();
                return read_only_view(&mesh.positions().data()->x, mesh.positions().size(), self);
            },
            "The mesh's vertices as the BVH sees them (float32 (N, 3), read-only).")
        .def_property_readonly(
            "triangles",
            [](const py::object& self) {
                const auto& mesh = self.cast<const CastMesh&>();
                return read_only_view(mesh.indices().data(), mesh.triangle_count(), self);
            },
            "The triangles (uint32 (M, 3), read-only); row i is primitive id i.")
        .def_property_readonly(
            "threads",
            [](const CastMesh& mesh) -> py::object {
                return mesh.threads() > 0 ? py::object(py::int_(mesh.threads())) : py::object(py::none());
            },
            "The thread count queries use unless they name one (None: all).")
        .def_property_readonly("bvh_bytes", &CastMesh::bvh_bytes, "Bytes of the BVH and its leaf triangles.")
        .def("__repr__", [](const CastMesh& mesh) {
            return "<sahara.RayCaster: " + std::to_string(mesh.positions().size()) + " vertices, " +
                   std::to_string(mesh.triangle_count()) + " triangles>";
        });
}

}  // namespace sahara::python
