#pragma once
/// The materials part of `sahara info`: each material with what it uses
/// (type, textures, vertex colours, emission, transmission, alpha, sidedness),
/// and what the scene gives that the renderer ignores.
#include "desc/scene_desc.h"
#include "render/stats.h"

namespace sahara {

/// Adds the "Materials" lines (counts by type, then one line per material) and
/// an "Ignored" line per material whose inputs are not rendered.
void describe_materials(StatsReport& s, const SceneDesc& d);

/// True if the material adds light of its own (emissive, or pbr/lambertian emission).
bool emits_light(const MaterialDesc& m);

}  // namespace sahara
