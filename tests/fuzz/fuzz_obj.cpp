// libFuzzer target for the OBJ loader. The input is an .obj; if it contains a
// line "#MTL", everything after it becomes fuzz.mtl beside it (seeds say
// `mtllib fuzz.mtl`), so the MTL parser is fuzzed too. Bad input must end in
// sahara::InputError, nothing else.
#include <cstring>
#include <string_view>

#include "base/error.h"
#include "base/log.h"
#include "fuzz_common.h"
#include "io/model_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    sahara::set_log_quiet(true);
    const auto& dir = sahara_fuzz::scratch_dir();
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    const size_t split = text.find("#MTL\n");
    const size_t obj_size = split == std::string_view::npos ? size : split;
    sahara_fuzz::write_file(dir / "fuzz.obj", data, obj_size);
    if (split != std::string_view::npos)
        sahara_fuzz::write_file(dir / "fuzz.mtl", data + split + 5, size - split - 5);
    else
        std::filesystem::remove(dir / "fuzz.mtl");
    try {
        sahara::load_obj(dir / "fuzz.obj");
    } catch (const sahara::InputError&) {
    }
    return 0;
}
