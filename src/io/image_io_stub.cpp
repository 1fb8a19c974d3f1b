// Temporary stand-in for the lead's image_io.cpp on the loaders branch: reads
// the whole file and decodes it in memory. Replaced at merge.
#include <fstream>
#include <iterator>
#include <vector>

#include "base/error.h"
#include "io/image_bytes.h"
#include "io/image_io.h"

namespace sahara {

std::shared_ptr<const Image> read_image(const std::filesystem::path& file, bool srgb_to_linear) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw input_error(file.string(), "", "cannot open image file");
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.empty()) throw input_error(file.string(), "", "image file is empty");
    return decode_image_bytes(bytes.data(), bytes.size(), srgb_to_linear, file.string(), "");
}

}  // namespace sahara
