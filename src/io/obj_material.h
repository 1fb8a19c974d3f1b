#pragma once
/// Internals of the OBJ loader: MTL materials -> MaterialDesc, and the checks
/// of the text that tinyobjloader does not make (encoding, malformed numbers).
#include <tiny_obj_loader.h>
#include <type_traits>

#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "io/model_loader.h"

namespace sahara::obj {

// CMake compiles the files that include this with the double build's define.
static_assert(std::is_same_v<tinyobj::real_t, double>, "OBJ files are read in double");

/// Refuses UTF-16 and UTF-32 text, recognised by its byte-order mark, naming the encoding.
void check_encoding(const std::string& file, const std::string& text);

/// OBJ v/vt/vn lines: NaN/Inf refused (InputError naming the element), a
/// malformed number such as "3.1+e2" (which tinyobjloader reads as 3.1) warned
/// about with file and line.
void check_obj_numbers(const std::string& file, const std::string& text);

/// The keywords each material of an MTL file sets (lower-case), so that a key
/// written as 0 can be told from one left out; malformed numbers warned about
/// with file and line.
using MtlKeys = std::map<std::string, std::set<std::string>>;
MtlKeys scan_mtl(const std::string& file, const std::string& text);

/// Loads MTL textures once per (file, use) and turns them into TextureDesc.
class ObjTextures {
   public:
    /// What a texture is used for decides its decoding.
    enum class Use { color, alpha, data, bump };

    ObjTextures(LoadedModel& model, std::filesystem::path mtl_dir)
        : model_(model), dir_(std::move(mtl_dir)) {}

    /// Index into model.textures, or -1 (with a warning) when the file is missing.
    int get(const std::string& name, const tinyobj::texture_option_t& opt, Use use, const std::string& what);
    /// map_Pr (roughness, into G) and map_Pm (metallic, into B) packed as glTF's
    /// metallic-roughness texture; -1 if neither is there.
    int metallic_roughness(const tinyobj::material_t& m);

   private:
    int add(std::shared_ptr<const Image> image, const std::string& path,
            const tinyobj::texture_option_t& opt);

    LoadedModel& model_;
    std::filesystem::path dir_;
    std::map<std::pair<std::string, int>, int> cache_;
};

/// MTL -> MaterialDesc (rules in docs/scene-format.md, "Materials of model files").
MaterialDesc convert_material(const tinyobj::material_t& m, const std::set<std::string>& keys,
                              ObjTextures& textures);

}  // namespace sahara::obj
