// KHR_materials_variants: the file's variant names, the caller's choice of one,
// and the material each primitive takes under it.
#include "base/error.h"
#include "base/text.h"
#include "io/gltf_detail.h"

namespace sahara::gltf {

namespace {

const char* kExt = "KHR_materials_variants";

/// A JSON integer in [0, size), or an InputError naming `element`.
size_t checked_index(const Source& src, const tinygltf::Value& v, size_t size, const char* what,
                     const std::string& element) {
    if (!v.IsInt()) throw input_error(src.file, element, std::string("must be a ") + what + " index");
    const int i = v.GetNumberAsInt();
    if (i < 0 || size_t(i) >= size)
        throw input_error(src.file, element,
                          std::string(what) + " " + std::to_string(i) + " does not exist (the file has " +
                              std::to_string(size) + ")");
    return size_t(i);
}

}  // namespace

std::vector<std::string> variant_names(const tinygltf::Model& model) {
    std::vector<std::string> out;
    auto ext = model.extensions.find(kExt);
    if (ext == model.extensions.end() || !ext->second.Has("variants")) return out;
    const tinygltf::Value& list = ext->second.Get("variants");
    for (size_t i = 0; list.IsArray() && i < list.ArrayLen(); ++i) {
        const tinygltf::Value& v = list.Get(int(i));
        out.push_back(v.Has("name") && v.Get("name").IsString() ? v.Get("name").Get<std::string>()
                                                                : "variant " + std::to_string(i));
    }
    return out;
}

size_t chosen_variant(const Source& src, const std::string& name) {
    const std::vector<std::string> names = variant_names(src.model);
    for (size_t i = 0; i < names.size(); ++i)
        if (names[i] == name) return i;
    throw input_error(src.file, kExt,
                      "no material variant named '" + name + "'" +
                          (names.empty() ? ", the file has none" : "; the file has: " + join(names)));
}

int variant_material(const Source& src, const tinygltf::Primitive& prim, const std::string& element) {
    auto ext = prim.extensions.find(kExt);
    if (!src.variant || ext == prim.extensions.end()) return prim.material;
    const std::string where = element + ".extensions." + kExt + ".mappings";
    if (!ext->second.IsObject() || !ext->second.Has("mappings") || !ext->second.Get("mappings").IsArray())
        throw input_error(src.file, where, "must be an array");
    const tinygltf::Value& mappings = ext->second.Get("mappings");
    const size_t variants = variant_names(src.model).size();
    int chosen = prim.material;
    bool found = false;
    // Every mapping is checked, not only the chosen one: a broken file is named, whichever variant is asked
    // for.
    for (size_t k = 0; k < mappings.ArrayLen(); ++k) {
        const tinygltf::Value& m = mappings.Get(int(k));
        const std::string at = where + "[" + std::to_string(k) + "]";
        if (!m.IsObject() || !m.Has("material") || !m.Has("variants") || !m.Get("variants").IsArray())
            throw input_error(src.file, at, "needs a material and a variants array");
        const size_t material =
            checked_index(src, m.Get("material"), src.model.materials.size(), "material", at + ".material");
        const tinygltf::Value& list = m.Get("variants");
        for (size_t v = 0; v < list.ArrayLen(); ++v) {
            const size_t variant = checked_index(src, list.Get(int(v)), variants, "variant",
                                                 at + ".variants[" + std::to_string(v) + "]");
            if (variant == *src.variant && !found) {
                chosen = int(material);
                found = true;
            }
        }
    }
    return chosen;
}

}  // namespace sahara::gltf
