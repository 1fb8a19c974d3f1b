#pragma once
/// Internals of the glTF loader shared by gltf_loader.cpp, gltf_accessor.cpp
/// and gltf_material.cpp. tinygltf types stay inside these three files.
#include <tiny_gltf.h>

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "io/model_loader.h"

namespace sahara::gltf {

/// A parsed glTF file plus what sahara needs to name it in messages.
struct Source {
    std::string file;           ///< as given, for messages
    std::filesystem::path dir;  ///< external URIs are relative to it
    tinygltf::Model model;
    /// Encoded bytes of images given as data: URIs, captured while tinygltf parses.
    std::map<int, std::vector<unsigned char>> data_uri_images;
};

/// Reads accessor `index` (referenced from `user`, e.g. "meshes[0].primitives[1].attributes.POSITION")
/// as `components` numbers per element. Normalized integers map to [0,1] / [-1,1]; other integers
/// keep their value. Applies sparse substitution. Throws InputError on any
/// out-of-range reference, read past the end of a buffer, or NaN/Inf.
std::vector<double> read_accessor(const Source& src, int index, const std::string& user, int components);

/// Reads an index accessor (unsigned byte/short/int scalars).
std::vector<uint32_t> read_indices(const Source& src, int index, const std::string& user);

/// Converts glTF materials (and their textures and images) on demand.
class Materials {
   public:
    Materials(const Source& src, LoadedModel& out);
    /// Index into out.materials for glTF material `index` (-1: a default material).
    uint32_t get(int index, const std::string& user);
    /// The TEXCOORD set the material's base colour (else emissive) texture reads.
    int texcoord_set(int index) const;

   private:
    MaterialDesc convert(const tinygltf::Material& m, const std::string& element);
    int texture(const tinygltf::TextureInfo& info, bool srgb, const std::string& element);
    std::shared_ptr<const Image> image(int index, bool srgb, const std::string& element);
    std::shared_ptr<const Image> decode_buffer_view_image(const tinygltf::Image& img, bool srgb,
                                                          const std::string& element);

    const Source& src_;
    LoadedModel& out_;
    std::map<int, uint32_t> converted_;
    std::map<std::string, int> texture_keys_;
    std::map<std::pair<int, bool>, std::shared_ptr<const Image>> images_;
};

/// Walks the default scene (node transforms, then `world_from_model`) into
/// meshes, cameras and lights of `out`; drops zero-area triangles.
void build_scene(const Source& src, const Mat4& world_from_model, LoadedModel& out);

/// Percent-decodes a URI reference ("my%20file.bin" -> "my file.bin").
std::string uri_decode(const std::string& uri);

}  // namespace sahara::gltf
