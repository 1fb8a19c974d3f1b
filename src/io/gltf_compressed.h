#pragma once
/// Compressed glTF geometry (KHR_draco_mesh_compression, EXT_meshopt_compression):
/// decoded right after tinygltf has parsed the file into new buffers that the
/// affected bufferViews and accessors are pointed at, so that the decoded data
/// goes through the same accessor reads and checks as uncompressed data.
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "io/gltf_detail.h"

namespace sahara::gltf {

inline constexpr const char* kMeshopt = "EXT_meshopt_compression";
inline constexpr const char* kDraco = "KHR_draco_mesh_compression";

/// The whole file again, changed where tinygltf would refuse a compressed file
/// before sahara decodes it (see gltf_compressed.cpp); nothing if unchanged.
/// `json` is the JSON text inside `file_bytes`.
std::optional<std::vector<unsigned char>> prepared_for_tinygltf(const std::vector<unsigned char>& file_bytes,
                                                                std::string_view json, bool glb);

/// Decodes each bufferView with EXT_meshopt_compression into a buffer of its own.
void decode_meshopt_views(Source& src);

/// Decodes each primitive's KHR_draco_mesh_compression bitstream into its accessors.
void decode_draco_primitives(Source& src);

/// Appends `bytes` (4-byte aligned) to buffers[buffer] as a new bufferView; returns its index.
int append_buffer_view(Source& src, int buffer, const std::vector<unsigned char>& bytes);

}  // namespace sahara::gltf
