#pragma once
/// The work units of a distributed render and their wire format (internal to
/// mpi_render.cpp; a header of its own so the tests can check the encoding).
#include <atomic>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "base/counters.h"
#include "math/vec3.h"
#include "render/camera.h"
#include "render/film.h"
#include "render/renderer.h"
#include "render/sampler.h"
#include "scene/scene.h"

namespace sahara::mpi_work {

/// Message tags.
enum Tag : int {
    kTagHello = 1,   ///< worker -> 0: uint32 thread count; ready for units
    kTagWork = 2,    ///< 0 -> worker: one unit (encode_work)
    kTagResult = 3,  ///< worker -> 0: a unit's new state (encode_result)
    kTagStop = 4,    ///< 0 -> worker: return what you hold, then kTagDone
    kTagLeave = 5,   ///< worker -> 0: this rank was signalled; send it nothing more
    kTagDone = 6,    ///< worker -> 0: WorkerReport; the worker holds nothing and exits
};

/// Exact accumulator state of one pixel (Film::sum, sum_sq, count).
struct PixelState {
    Vec3d sum;
    double sum_sq = 0;
    uint32_t count = 0, unused = 0;
};

/// One unit: bring every pixel of `rect` to its target sample count.
struct TileWork {
    uint32_t tile = 0;
    TileRect rect{0, 0, 0, 0};
    std::vector<uint32_t> targets;  ///< per pixel of rect, row-major
    std::vector<PixelState> state;  ///< per pixel of rect, row-major
    uint64_t samples = 0;           ///< taken by this unit (result)
    uint64_t nonfinite = 0;         ///< discarded by this unit (result)
    double seconds = 0;             ///< render time of this unit (result)

    size_t pixels() const { return size_t(rect.x1 - rect.x0) * size_t(rect.y1 - rect.y0); }
};

/// What a worker reports when it leaves: its counters and timings.
struct WorkerReport {
    Counters counters;
    uint64_t units = 0;
    double render_seconds = 0;  ///< summed over its threads
    double wait_seconds = 0;    ///< threads idle waiting for a unit (communication)
    uint32_t threads = 0, unused = 0;
};

/// Renders `w` from its state to its targets (the image-sized camera), stopping
/// at the next pixel when `stop` is raised; updates state, samples, nonfinite.
inline void render_work(const Scene& scene, const Camera& camera, TileWork& w,
                        const std::atomic<bool>& stop) {
    const int tw = w.rect.x1 - w.rect.x0, th = w.rect.y1 - w.rect.y0;
    Film film(tw, th);
    for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x) {
            const PixelState& p = w.state[size_t(y) * size_t(tw) + size_t(x)];
            film.set_pixel_state(x, y, p.sum, p.sum_sq, p.count);
        }
    Sampler sampler(scene.render.seed, scene.render.sampler);
    w.samples = 0;
    for (int y = 0; y < th && !stop.load(std::memory_order_relaxed); ++y)
        for (int x = 0; x < tw && !stop.load(std::memory_order_relaxed); ++x) {
            const uint32_t begin = film.count(x, y), end = w.targets[size_t(y) * size_t(tw) + size_t(x)];
            if (end <= begin) continue;
            render_pixel_samples(scene, camera, film, sampler, w.rect.x0 + x, w.rect.y0 + y, x, y, begin,
                                 end);
            w.samples += end - begin;
        }
    for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x)
            w.state[size_t(y) * size_t(tw) + size_t(x)] = {film.sum(x, y), film.sum_sq(x, y),
                                                           film.count(x, y), 0};
    w.nonfinite = film.nonfinite_samples();
}

/// Appends trivially copyable values to a byte buffer.
class Writer {
   public:
    template <class T>
    void put(const T& v) {
        const size_t at = bytes.size();
        bytes.resize(at + sizeof(T));
        std::memcpy(bytes.data() + at, &v, sizeof(T));
    }
    template <class T>
    void put_all(const std::vector<T>& v) {
        const size_t at = bytes.size();
        bytes.resize(at + v.size() * sizeof(T));
        if (!v.empty()) std::memcpy(bytes.data() + at, v.data(), v.size() * sizeof(T));
    }
    std::vector<char> bytes;
};

/// Reads what Writer wrote; throws std::runtime_error on a short message.
class Reader {
   public:
    explicit Reader(const std::vector<char>& b) : bytes_(b) {}
    template <class T>
    T get() {
        T v;
        take(&v, sizeof(T));
        return v;
    }
    template <class T>
    void get_all(std::vector<T>& v, size_t n) {
        v.resize(n);
        take(v.data(), n * sizeof(T));
    }
    bool at_end() const { return pos_ == bytes_.size(); }

   private:
    void take(void* out, size_t n) {
        if (n > bytes_.size() - pos_) throw std::runtime_error("sahara: truncated MPI message");
        if (n) std::memcpy(out, bytes_.data() + pos_, n);
        pos_ += n;
    }
    const std::vector<char>& bytes_;
    size_t pos_ = 0;
};

inline std::vector<char> encode_work(const TileWork& w) {
    Writer out;
    out.put(w.tile);
    out.put(w.rect);
    out.put_all(w.targets);
    out.put_all(w.state);
    return std::move(out.bytes);
}

inline TileWork decode_work(const std::vector<char>& bytes) {
    Reader in(bytes);
    TileWork w;
    w.tile = in.get<uint32_t>();
    w.rect = in.get<TileRect>();
    if (w.rect.x1 < w.rect.x0 || w.rect.y1 < w.rect.y0)
        throw std::runtime_error("sahara: bad tile in MPI message");
    in.get_all(w.targets, w.pixels());
    in.get_all(w.state, w.pixels());
    if (!in.at_end()) throw std::runtime_error("sahara: oversized MPI work message");
    return w;
}

inline std::vector<char> encode_result(const TileWork& w) {
    Writer out;
    out.put(w.tile);
    out.put(w.samples);
    out.put(w.nonfinite);
    out.put(w.seconds);
    out.put_all(w.state);
    return std::move(out.bytes);
}

/// The tile a work or result message is about.
inline uint32_t peek_tile(const std::vector<char>& bytes) { return Reader(bytes).get<uint32_t>(); }

/// Decodes a result into `w`, whose tile and rect rank 0 knows already.
inline void decode_result(const std::vector<char>& bytes, TileWork& w) {
    Reader in(bytes);
    w.tile = in.get<uint32_t>();
    w.samples = in.get<uint64_t>();
    w.nonfinite = in.get<uint64_t>();
    w.seconds = in.get<double>();
    in.get_all(w.state, w.pixels());
    if (!in.at_end()) throw std::runtime_error("sahara: oversized MPI result message");
}

}  // namespace sahara::mpi_work
