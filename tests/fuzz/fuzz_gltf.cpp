// libFuzzer target for the glTF loader: inputs starting with "glTF" are
// written as a .glb, others as a .gltf (JSON with data: URI buffers), so both
// containers are fuzzed. Bad input must end in sahara::InputError, nothing else.
#include <cstring>

#include "base/error.h"
#include "base/log.h"
#include "fuzz_common.h"
#include "io/model_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    sahara::set_log_quiet(true);
    const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    const auto file = sahara_fuzz::scratch_dir() / (glb ? "fuzz.glb" : "fuzz.gltf");
    sahara_fuzz::write_file(file, data, size);
    try {
        sahara::load_gltf(file);
    } catch (const sahara::InputError&) {
    }
    return 0;
}
