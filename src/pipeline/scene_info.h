#pragma once
/// What a scene holds (objects, triangles, materials, textures, lights,
/// bounds), its estimated memory and its features: the report of `sahara info`
/// and of the Python module's Scene.info().
#include "desc/scene_desc.h"
#include "render/stats.h"
#include "scene/scene.h"

namespace sahara {

/// The report for `desc` and the scene built from it (no timings).
StatsReport describe_scene(const SceneDesc& desc, const Scene& scene);

}  // namespace sahara
