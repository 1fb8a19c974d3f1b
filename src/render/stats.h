#pragma once
/// Grouped statistics, printed pbrt-style ("Render/Camera rays ...") by
/// `render --stats` and `sahara info`, or as JSON for scripts.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/scene.h"

namespace sahara {

class StatsReport {
   public:
    /// Adds a line; groups print in the order they first appear.
    void add(const std::string& group, const std::string& name, const std::string& text,
             nlohmann::json value);
    void add_count(const std::string& group, const std::string& name, uint64_t n);
    void add_bytes(const std::string& group, const std::string& name, uint64_t bytes);
    void add_seconds(const std::string& group, const std::string& name, double seconds);
    void add_ratio(const std::string& group, const std::string& name, double value, const std::string& unit);

    void print(std::FILE* out) const;
    /// {"Group": {"Name": value, ...}, ...}
    nlohmann::json to_json() const;

   private:
    struct Line {
        std::string group, name, text;
        nlohmann::json value;
    };
    std::vector<Line> lines_;
};

/// Bytes the runtime scene keeps per kind of data.
struct SceneMemory {
    uint64_t spheres = 0, triangles = 0, other_geometry = 0, textures = 0;
    /// Estimate for a binary BVH: about 2 nodes of 32 bytes per primitive plus
    /// a 4-byte index each, until the accelerator reports its own size; plus the
    /// instance level's trees and records (built, so measured).
    uint64_t bvh_estimate = 0;
    uint64_t total() const { return spheres + triangles + other_geometry + textures + bvh_estimate; }
};

SceneMemory estimate_scene_memory(const Scene& scene);

/// Bytes of decoded texel data (RGBA float).
uint64_t texture_bytes(const TextureDesc& t);

/// "12.3 MiB" style.
std::string format_bytes(uint64_t bytes);

}  // namespace sahara
