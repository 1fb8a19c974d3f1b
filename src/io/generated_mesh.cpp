#include "io/generated_mesh.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sahara {

SphereGrid sphere_grid_for(size_t triangles) {
    if (triangles < 6 || triangles % 2 != 0)
        throw std::invalid_argument("a closed sphere grid has an even number of triangles, at least 6; got " +
                                    std::to_string(triangles));
    const size_t half = triangles / 2;  // rings * segments
    if (half + 2 > std::numeric_limits<uint32_t>::max())
        throw std::invalid_argument(std::to_string(triangles) +
                                    " triangles need more vertices than 32-bit indices reach");
    // Segments about twice the rings (longitude spans twice latitude's angle) makes
    // the quads near the equator square; among the exact factorisations take the closest.
    const double ideal_rings = std::sqrt(double(half) / 2.0);
    SphereGrid best;
    double best_error = std::numeric_limits<double>::infinity();
    auto consider = [&](size_t rings) {
        const size_t segments = half / rings;
        const double error = std::abs(std::log(double(rings) / ideal_rings));
        if (segments >= 3 && error < best_error) {
            best = {uint32_t(rings), uint32_t(segments)};
            best_error = error;
        }
    };
    for (size_t d = 1; d * d <= half; ++d)
        if (half % d == 0) {
            consider(d);
            consider(half / d);
        }
    return best;
}

namespace {

/// Radius at polar angle theta (0 at the top pole) and azimuth phi: waves deep enough
/// that diffuse bounces hit the surface again, and that vanish
/// towards the poles (the sin(theta) factor), so the pole vertices have one radius.
/// A radial displacement of a sphere with a positive radius stays star-shaped around
/// the centre, so the surface cannot intersect itself.
double displaced_radius(double theta, double phi) {
    const double s = std::sin(theta);
    return 1.0 + 0.02 * std::cos(2.0 * theta) +
           s * (0.15 * std::cos(3.0 * phi) * std::sin(4.0 * theta) +
                0.08 * std::sin(7.0 * phi + 1.0) * std::cos(9.0 * theta));
}

Vec3 sphere_point(double theta, double phi) {
    const double r = displaced_radius(theta, phi);
    return Vec3(float(r * std::sin(theta) * std::cos(phi)), float(r * std::cos(theta)),
                float(r * std::sin(theta) * std::sin(phi)));
}

}  // namespace

TriangleMesh make_displaced_sphere(const SphereGrid& grid) {
    const int64_t rings = grid.rings, segs = grid.segments;
    const double pi = 3.14159265358979323846;
    TriangleMesh mesh;
    mesh.name = "generated displaced sphere (" + std::to_string(grid.triangles()) + " triangles)";
    mesh.positions.resize(size_t(rings * segs + 2));
    mesh.indices.resize(3 * grid.triangles());
    // Vertex 0 is the top pole, 1 + i * segs + j vertex j of ring i, the last the bottom pole.
    const auto bottom = uint32_t(rings * segs + 1);
    mesh.positions[0] = sphere_point(0.0, 0.0);
    mesh.positions[bottom] = sphere_point(pi, 0.0);
    auto vertex = [segs](int64_t ring, int64_t j) { return uint32_t(1 + ring * segs + j % segs); };
#pragma omp parallel for schedule(static)
    for (int64_t i = 0; i < rings; ++i) {
        const double theta = pi * double(i + 1) / double(rings + 1);
        for (int64_t j = 0; j < segs; ++j)
            mesh.positions[vertex(i, j)] = sphere_point(theta, 2.0 * pi * double(j) / double(segs));
        // Ring i's triangles: its pole fan (first and last ring), then the band below it.
        // Counter-clockwise seen from outside, so every shared edge runs once each way.
        uint32_t* out = &mesh.indices[size_t(3 * (i == 0 ? 0 : segs + 2 * segs * (i - 1)))];
        auto emit = [&out](uint32_t a, uint32_t b, uint32_t c) {
            out[0] = a, out[1] = b, out[2] = c;
            out += 3;
        };
        if (i == 0)
            for (int64_t j = 0; j < segs; ++j) emit(0, vertex(0, j + 1), vertex(0, j));
        if (i > 0)
            for (int64_t j = 0; j < segs; ++j) {
                const uint32_t a = vertex(i - 1, j), b = vertex(i - 1, j + 1);
                const uint32_t c = vertex(i, j), d = vertex(i, j + 1);
                emit(a, b, c);
                emit(b, d, c);
            }
        if (i == rings - 1)
            for (int64_t j = 0; j < segs; ++j) emit(bottom, vertex(i, j), vertex(i, j + 1));
    }
    return mesh;
}

}  // namespace sahara
