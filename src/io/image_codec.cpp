// Finds and loads the image codec plugin (image_codec.h).
#include "base/text.h"
#include "io/image_codec.h"

#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <filesystem>

#include "base/error.h"

// Defined when the codec is linked in (the fuzz targets); null otherwise.
extern "C" const sahara::ImageCodecApi* sahara_image_codec_api() __attribute__((weak));

namespace sahara {
namespace {

namespace fs = std::filesystem;

fs::path executable_dir() {
    char buf[PATH_MAX];
    const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
    if (n <= 0) return {};
    buf[n] = '\0';
    return fs::path(buf).parent_path();
}

/// The directory of the shared object this code is linked into (the Python
/// extension module), or empty when it is linked into the executable itself.
fs::path shared_object_dir() {
    Dl_info info{};
    if (::dladdr(reinterpret_cast<void*>(&shared_object_dir), &info) == 0 || !info.dli_fname) return {};
    const fs::path file(info.dli_fname);
    if (!file.is_absolute() || file.extension() != ".so") return {};  // the executable: not ours to add
    return file.parent_path();
}

/// The file set_image_codec_file named; empty: none.
std::string& chosen_codec_file() {
    static std::string file;
    return file;
}

/// Where the plugin may be, in the order tried (see kImageCodecLibrary).
std::vector<fs::path> candidate_files() {
    if (const std::string& chosen = chosen_codec_file(); !chosen.empty()) return {chosen};
    std::vector<fs::path> files;
    // Inside a Python interpreter the executable is python3: the module keeps its plugin beside itself.
    if (const fs::path own = shared_object_dir(); !own.empty()) files.push_back(own / kImageCodecLibrary);
    const fs::path dir = executable_dir();
    if (dir.empty()) return files;
    files.push_back(dir / kImageCodecLibrary);
#ifdef SAHARA_CODEC_RELATIVE_DIR
    // The installed layout's bin -> plugin directory, computed by CMake.
    files.push_back((dir / SAHARA_CODEC_RELATIVE_DIR / kImageCodecLibrary).lexically_normal());
#endif
    return files;
}

struct Loaded {
    const ImageCodecApi* api = nullptr;
    std::string error;
};

Loaded load() {
    if (sahara_image_codec_api) return {sahara_image_codec_api(), ""};
    const ImageCodecSearch search = find_image_codec();
    if (search.found.empty()) {
        return {nullptr, "the image codec plugin is missing (looked for " + join(search.tried) +
                             "; build the target sahara_image_codec, or install sahara again)"};
    }
    const std::string& file = search.found;
    void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) return {nullptr, "cannot load the image codec " + file + ": " + ::dlerror()};
    using Entry = const ImageCodecApi* (*)();
    const auto entry = reinterpret_cast<Entry>(::dlsym(handle, kImageCodecSymbol));
    const ImageCodecApi* api = entry ? entry() : nullptr;
    if (!api || api->version != kImageCodecVersion)
        return {nullptr, "the image codec " + file + " is from another build of sahara (rebuild it)"};
    return {api, ""};
}

}  // namespace

void set_image_codec_file(const std::string& file) { chosen_codec_file() = file; }

ImageCodecSearch find_image_codec() {
    ImageCodecSearch search;
    for (const fs::path& file : candidate_files()) {
        search.tried.push_back(file.string());
        std::error_code ec;
        if (fs::exists(file, ec)) {
            search.found = file.string();
            break;
        }
    }
    return search;
}

const ImageCodecApi& image_codec(const std::string& file_for_errors) {
    static const Loaded loaded = load();  // once, thread-safe
    if (!loaded.api) throw input_error(file_for_errors, "", loaded.error);
    return *loaded.api;
}

}  // namespace sahara
