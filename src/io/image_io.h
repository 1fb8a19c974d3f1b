#pragma once
/// Image files through OpenImageIO (loaded on first use, see image_codec.h). Reading gives linear RGBA float;
/// writing picks the format by extension (.png: sRGB 8-bit; .exr/.hdr/.pfm: linear float) and is atomic: a
/// temporary file in the same directory, then rename, so an interrupted run never leaves a truncated image.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "desc/scene_desc.h"

namespace sahara {

/// Reads an image; `srgb_to_linear` decodes 8-bit sRGB colour data (textures).
/// Throws InputError naming the file on failure or if a side exceeds 32768.
std::shared_ptr<const Image> read_image(const std::filesystem::path& file, bool srgb_to_linear);

/// Key/value metadata stored in the file (scene, spp, seed, render time, version).
using ImageMetadata = std::vector<std::pair<std::string, std::string>>;

/// Whether `file`'s extension is an output format sahara writes.
bool is_supported_output(const std::filesystem::path& file);
/// Whether the format stores linear float (no tone mapping is applied).
bool is_hdr_output(const std::filesystem::path& file);

/// Checks before rendering that `file` can be written (extension, directory
/// exists, image codec loads). Throws InputError with a clear message otherwise.
void check_output_path(const std::filesystem::path& file);

/// A named per-pixel uint32 channel, stored losslessly in EXR files (other
/// formats drop it). sahara keeps its exact render state this way for --resume.
struct ExtraChannel {
    std::string name;
    std::vector<uint32_t> values;  ///< width * height, row-major
};

/// Writes width x height RGB pixels (row 0 at the top). For 8-bit formats the
/// values must already be display-referred in [0,1] linear; they are sRGB-encoded
/// here. Returns normally only when the complete file is in place.
void write_image(const std::filesystem::path& file, int width, int height, const std::vector<float>& rgb,
                 const ImageMetadata& metadata = {}, const std::vector<ExtraChannel>& extra = {});

/// Writes 8-bit pixels as they are (1-4 interleaved channels, no colour
/// conversion, not atomic): for tests and tools that need a small image file.
void write_image_u8(const std::filesystem::path& file, int width, int height, int channels,
                    const unsigned char* data);

/// The metadata write_image stored (keys without the "sahara:" prefix); empty
/// for files sahara did not write. Throws InputError if the file cannot be opened.
ImageMetadata read_image_metadata(const std::filesystem::path& file);

/// Reads the named uint32 channels of an EXR written with extra channels.
/// Throws InputError naming the file and the channel if one is missing.
std::vector<ExtraChannel> read_extra_channels(const std::filesystem::path& file,
                                              const std::vector<std::string>& names, int* width, int* height);

/// IEC 61966-2-1 sRGB transfer functions.
float srgb_encode(float linear);
float srgb_decode(float encoded);

}  // namespace sahara
