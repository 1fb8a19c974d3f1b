#pragma once
/// The BVH statistics of `sahara bvh --json` (and the Python module's
/// Scene.bvh_stats()): tree shape, SAH cost, memory, build time and the mean
/// traversal work of primary, diffuse-bounce and shadow rays.
#include <nlohmann/json.hpp>

#include <optional>
#include <string>

#include "base/bvh_choice.h"
#include "scene/scene.h"

namespace sahara {

struct BvhReportOptions {
    std::optional<BvhBuilder> builder;  ///< none: the scene's render.bvh_builder
    std::optional<BvhLayout> layout;    ///< none: the default layout
    int threads = 0;                    ///< build threads, 0 = all
    int width = 1024, height = 1024;    ///< the primary-ray grid
    bool from_scene_file = false;       ///< aim through the scene's camera, not at the bounds
};

/// Builds the BVH of `scene`'s bounded primitives and reports on it; `file`
/// names the input in the report.
nlohmann::ordered_json bvh_report(const Scene& scene, const std::string& file,
                                  const BvhReportOptions& options);

/// The instance level of a scene with instances (null JSON without): the top-level
/// tree's shape, prototypes, instances, triangles stored and drawn, and bytes. The
/// rest of a bvh or bench report is about the scene's own (flat) tree.
nlohmann::ordered_json instance_level_json(const Scene& scene);

}  // namespace sahara
