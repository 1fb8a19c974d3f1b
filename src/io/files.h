#pragma once
/// The one whole-file reader, the one output writer and the one extension check of sahara: every
/// command and loader reads input files and decides a file's kind here, so a
/// missing file reads the same everywhere and `MODEL.OBJ` works like `model.obj`.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace sahara {

/// The whole content of `file`. Throws InputError naming the file: "no such
/// file", "is a directory, not a regular file", "not a regular file", the
/// system's reason it cannot be opened, or "read error". `what` ("scene file",
/// "ray file") prefixes the reason with "cannot open WHAT: "; empty: the reason alone.
std::string read_file(const std::filesystem::path& file, const std::string& what = "");
/// The same, as bytes (binary formats such as .glb).
std::vector<unsigned char> read_file_bytes(const std::filesystem::path& file, const std::string& what = "");

/// The one way sahara writes an output file: `write(tmp)` writes a temporary beside
/// `file` (hidden, same extension, so a codec picks the same writer) and returns "" or
/// why it failed; the temporary is then renamed onto `file`. A signal during the write
/// removes the temporary; on any failure no temporary is left and InputError names
/// `file`. `what` ("image", "plot") names the output in the rename failure.
void write_via_temporary(const std::filesystem::path& file,
                         const std::function<std::string(const std::filesystem::path& tmp)>& write,
                         const std::string& what);

/// What a file is, by its extension, case-insensitively.
enum class FileKind {
    scene,  ///< .json
    obj,    ///< .obj
    gltf,   ///< .gltf (JSON) and .glb (binary)
    png,
    exr,
    hdr,
    pfm,
    other,  ///< anything else, no extension included
};

FileKind file_kind(const std::filesystem::path& file);
/// The extension in lower case with its dot (".glb"), empty if none.
std::string lower_extension(const std::filesystem::path& file);

/// A model file (.obj, .gltf, .glb): what `load_model` and `sahara view` read.
inline bool is_model_kind(FileKind k) { return k == FileKind::obj || k == FileKind::gltf; }
/// An image format sahara writes (.png, .exr, .hdr, .pfm).
inline bool is_output_image_kind(FileKind k) {
    return k == FileKind::png || k == FileKind::exr || k == FileKind::hdr || k == FileKind::pfm;
}

}  // namespace sahara
