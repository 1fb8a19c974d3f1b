#pragma once
/// Internals of the glTF loader shared by gltf_loader.cpp, gltf_accessor.cpp
/// and gltf_material.cpp. tinygltf types stay inside these three files.
#include <tiny_gltf.h>

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
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
    /// The KHR_materials_variants variant to render (its index); none: the default materials.
    std::optional<size_t> variant;
};

/// The bytes of bufferViews[bv], checked to lie inside their buffer.
std::span<const unsigned char> buffer_view_bytes(const Source& src, int bv, const std::string& element);

/// Reads accessor `index` (referenced from `user`, e.g. "meshes[0].primitives[1].attributes.POSITION")
/// as `components` numbers per element. Normalized integers map to [0,1] / [-1,1]; other integers
/// keep their value. Applies sparse substitution. Throws InputError on any
/// out-of-range reference, read past the end of a buffer, or NaN/Inf.
std::vector<double> read_accessor(const Source& src, int index, const std::string& user, int components);

/// Reads an index accessor (unsigned byte/short/int scalars).
std::vector<uint32_t> read_indices(const Source& src, int index, const std::string& user);

/// A textureInfo: core (tinygltf::TextureInfo) or inside an extension object.
struct TextureRef {
    int index = -1;
    int texcoord = 0;
    const tinygltf::Value* transform = nullptr;  ///< KHR_texture_transform, if present
};

/// Converts glTF materials (and their textures and images) on demand.
class Materials {
   public:
    Materials(const Source& src, LoadedModel& out);
    /// Index into out.materials for glTF material `index` (-1: a default material),
    /// used by a primitive with COLOR_0 if `vertex_colors`.
    uint32_t get(int index, const std::string& user, bool vertex_colors);

   private:
    MaterialDesc convert(const tinygltf::Material& m, const std::string& element);
    void set_base_color(MaterialDesc& out, const tinygltf::Material& m, const std::string& element);
    MaterialDesc convert_unlit(const tinygltf::Material& m, const std::string& element, MaterialDesc out);
    void set_alpha(MaterialDesc& out, const tinygltf::Material& m, float factor_alpha, int base_tex,
                   const std::string& element);
    void set_emission(MaterialDesc& out, const tinygltf::Material& m, const std::string& element);
    void set_extensions(MaterialDesc& out, const tinygltf::Material& m, const std::string& element);
    void set_clearcoat(PbrLayersDesc& out, const tinygltf::Value& ext, const std::string& element);
    void set_sheen(PbrLayersDesc& out, const tinygltf::Value& ext, const std::string& element);
    void set_anisotropy(MaterialDesc& out, const tinygltf::Value& ext, const std::string& element);
    void set_iridescence(MaterialDesc& out, const tinygltf::Value& ext, const std::string& element);
    void set_dispersion(MaterialDesc& out, const tinygltf::Value& ext, const std::string& element);
    void set_diffuse_transmission(MaterialDesc& out, const tinygltf::Value& ext, const std::string& element);
    float bounded_number(const tinygltf::Value& ext, const char* key, double fallback, double low,
                         double high, const std::string& element) const;
    std::optional<TextureRef> texture_info(const tinygltf::Value& ext, const char* key) const;
    int texture(const tinygltf::TextureInfo& info, bool srgb, const std::string& element);
    int texture(const TextureRef& ref, bool srgb, const std::string& element);
    /// A texture's sampler, uv transform and decoded image (null if it cannot be
    /// read), not yet added to the model; `cache_key` says which texture() keeps.
    std::optional<TextureDesc> texture_desc(const TextureRef& ref, bool srgb, const std::string& element,
                                            std::string* cache_key, bool* from_webp = nullptr);
    /// Names EXT_texture_webp among the material's extensions if one of its textures came from WebP.
    void note_webp(MaterialDesc& out) const;
    void set_specular(MaterialDesc& out, const tinygltf::Value& ext, const std::string& where);
    /// KHR_materials_pbrSpecularGlossiness converted to metallic-roughness (gltf_spec_gloss.cpp).
    void convert_spec_gloss(MaterialDesc& out, const tinygltf::Material& m, const tinygltf::Value& ext,
                            const std::string& element);
    std::shared_ptr<const Image> image(int index, bool srgb, const std::string& element);
    int webp_source(const tinygltf::Texture& tex) const;
    std::shared_ptr<const Image> webp_image(int webp, int fallback, bool srgb, const std::string& tex_name,
                                            int* used);
    std::shared_ptr<const Image> decode_buffer_view_image(const tinygltf::Image& img, bool srgb,
                                                          const std::string& element);

    const Source& src_;
    LoadedModel& out_;
    std::map<int, uint32_t> converted_;
    std::map<std::string, int> texture_keys_;
    std::map<std::pair<int, bool>, std::shared_ptr<const Image>> images_;
    std::set<std::string> ignored_;  ///< extensions already warned about
    std::set<int> webp_textures_;    ///< indices into out_.textures decoded from EXT_texture_webp images
};

/// Primitive `p` of mesh `mesh` in model space: triangles, normals, both uv sets,
/// COLOR_0 and TANGENT, with morph target i added at `weights[i]`. Nothing for
/// points, lines and primitives without POSITION (with a warning). No material.
std::optional<TriangleMesh> read_primitive(const Source& src, size_t mesh, size_t p,
                                           const std::vector<double>& weights);

/// Linear blend skinning of `mesh` (read from `prim`) by JOINTS_n/WEIGHTS_n with
/// `joint_matrices[k]` = world matrix of skin joint k x its inverse bind matrix.
void apply_skin(const Source& src, const tinygltf::Primitive& prim, const std::string& element,
                const std::vector<Mat4>& joint_matrices, TriangleMesh& mesh);

/// EXT_mesh_gpu_instancing on `node`: one node-space matrix (T x R x S) per
/// instance, or nothing if the node does not use the extension.
std::optional<std::vector<Mat4>> gpu_instances(const Source& src, const tinygltf::Node& node,
                                               const std::string& node_element);

/// The names of the file's KHR_materials_variants ("variant N" where a name is missing).
std::vector<std::string> variant_names(const tinygltf::Model& model);

/// The index of the variant called `name`; an InputError listing the file's variants if none is.
size_t chosen_variant(const Source& src, const std::string& name);

/// The material `prim` (at `element`, e.g. "meshes[0].primitives[1]") takes under
/// `src.variant`: its mapping's, else its default. With a variant chosen, every
/// mapping of the primitive is checked (indices in range) and errors name it.
int variant_material(const Source& src, const tinygltf::Primitive& prim, const std::string& element);

/// Walks the default scene (node transforms, then `world_from_model`) into
/// meshes, cameras and lights of `out`; drops zero-area triangles.
void build_scene(const Source& src, const Mat4& world_from_model, SharedMeshes shared, LoadedModel& out);

/// Percent-decodes a URI reference ("my%20file.bin" -> "my file.bin").
std::string uri_decode(const std::string& uri);

}  // namespace sahara::gltf
