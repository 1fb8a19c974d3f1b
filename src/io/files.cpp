#include "io/files.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include "base/error.h"
#include "base/pending_file.h"

namespace sahara {

namespace fs = std::filesystem;

namespace {

/// Reads `file` into `Bytes` (std::string or a byte vector): the one reader behind both entry points.
template <class Bytes>
Bytes read_all(const fs::path& file, const std::string& what) {
    const std::string prefix = what.empty() ? "" : "cannot open " + what + ": ";
    auto fail = [&](const std::string& reason) { return input_error(file.string(), "", prefix + reason); };
    std::error_code ec;
    const fs::file_status status = fs::status(file, ec);
    if (!fs::exists(status)) throw fail("no such file");
    if (fs::is_directory(status)) throw fail("is a directory, not a regular file");
    if (!fs::is_regular_file(status)) throw fail("not a regular file");
    std::ifstream in(file, std::ios::binary | std::ios::ate);
    if (!in) throw fail(std::strerror(errno));
    const std::streamoff size = in.tellg();
    if (size < 0) throw fail("read error");
    Bytes bytes(size_t(size), 0);
    in.seekg(0);
    in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size));
    if (in.gcount() != std::streamsize(size)) throw fail("read error");
    return bytes;
}

}  // namespace

std::string read_file(const fs::path& file, const std::string& what) {
    return read_all<std::string>(file, what);
}

std::vector<unsigned char> read_file_bytes(const fs::path& file, const std::string& what) {
    return read_all<std::vector<unsigned char>>(file, what);
}

std::string lower_extension(const fs::path& file) {
    std::string ext = file.extension().string();
    for (char& c : ext)
        if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    return ext;
}

FileKind file_kind(const fs::path& file) {
    static const std::pair<const char*, FileKind> kinds[] = {
        {".json", FileKind::scene}, {".obj", FileKind::obj}, {".gltf", FileKind::gltf},
        {".glb", FileKind::gltf},   {".png", FileKind::png}, {".exr", FileKind::exr},
        {".hdr", FileKind::hdr},    {".pfm", FileKind::pfm}};
    const std::string ext = lower_extension(file);
    for (const auto& [name, kind] : kinds)
        if (ext == name) return kind;
    return FileKind::other;
}

void write_via_temporary(const fs::path& file, const std::function<std::string(const fs::path& tmp)>& write,
                         const std::string& what) {
    fs::path tmp = file;
    std::string name(".");  // built piecewise: gcc 12 warns falsely (-Wrestrict) on a + chain
    name.append(file.stem().string()).append(".tmp").append(std::to_string(::getpid()));
    name.append(file.extension().string());
    tmp.replace_filename(name);
    const PendingFile pending(tmp.string());  // a signal during the write removes the temporary
    std::error_code ec;
    if (const std::string why = write(tmp); !why.empty()) {
        fs::remove(tmp, ec);
        throw input_error(file.string(), "", why);
    }
    fs::rename(tmp, file, ec);
    if (ec) {
        const std::string why = ec.message();  // before remove() overwrites ec
        fs::remove(tmp, ec);
        throw input_error(file.string(), "", "cannot move the finished " + what + " into place: " + why);
    }
}

}  // namespace sahara
