#pragma once
/// OBJ and MTL text rewritten, before tinyobjloader tokenises it, into the form
/// it reads correctly: line continuations joined, and names with spaces kept
/// whole (tinyobjloader ends a `usemtl` name and an `mtllib` file name at the
/// first space, but reads a `newmtl` name to the end of the line).
#include <filesystem>
#include <string>

namespace sahara::obj {

/// The OBJ text with `\` + newline joined into one logical line (the OBJ
/// specification's continuation; blank lines follow so later line numbers stay
/// the file's), `usemtl` names with spaces encoded as encode_material_name does,
/// and an `mtllib` whose whole rest of line names a file in `dir` escaped as
/// one file name (otherwise its words are separate files, as the format says).
/// Data lines (v, vt, vn, f, ...) lose a trailing `# comment`, and face corners
/// an empty last slot (`f 1/1/ 2/2/ 3/3/`).
std::string prepare_obj_text(const std::string& text, const std::filesystem::path& dir);

/// The MTL text with `newmtl` names encoded to match prepare_obj_text's `usemtl`.
std::string prepare_mtl_text(const std::string& text);

/// A material name from prepared text back to the file's spelling.
std::string decode_material_name(std::string name);

}  // namespace sahara::obj
