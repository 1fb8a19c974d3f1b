#pragma once
/// The image codec: the only code that talks to OpenImageIO. It is built as a
/// plugin (libsahara_image_codec.so) and loaded on first use, because
/// OpenImageIO and the ~260 libraries it pulls in take about half a second to
/// load: `sahara --help`, `sahara bench` or a scene error should not pay that.
/// Callers use image_io.h and image_bytes.h; this header is their back end.
/// Every function reports failure as a message (empty: success) and leaves
/// naming the file to the caller, so no exception crosses the plugin boundary.
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace sahara {

struct PlotDrawing;  // io/plot.h
struct PlotText;     // io/plot.h

/// Decoded pixels: `channels` floats per pixel, row 0 at the top.
struct DecodedPixels {
    int width = 0, height = 0, channels = 0;
    int alpha_channel = -1;  ///< as the file declares it; -1 when it declares none
    std::vector<float> values;
};

/// One channel's storage in a written file.
enum class ChannelType : uint8_t { u8, f32, u32 };

/// What to write: interleaved channels of one byte each (all u8) or four bytes each.
struct PixelsToWrite {
    int width = 0, height = 0;
    std::vector<ChannelType> types;                               ///< one per channel
    std::vector<std::string> names;                               ///< empty: the format's default names
    const void* data = nullptr;                                   ///< width * height * types.size() values
    std::vector<std::pair<std::string, std::string>> attributes;  ///< metadata, stored as strings
    bool srgb = false;                                            ///< tag 8-bit colour as sRGB
    bool lossless_zip = false;                                    ///< EXR: zip compression (bit-exact)
};

/// The plugin's entry points (same compiler and standard library on both sides).
struct ImageCodecApi {
    int version;
    /// Decodes a file (by_memory == nullptr) or a buffer whose format `hint` names
    /// by extension ("x.png"). Refuses images with a side outside 1..max_side
    /// before allocating pixels; at most `max_channels` channels are read.
    std::string (*decode)(const std::string& name, const unsigned char* by_memory, size_t size, int max_side,
                          int max_channels, DecodedPixels& out);
    /// Writes `pixels` to `file` (the format follows the extension).
    std::string (*encode)(const std::string& file, const PixelsToWrite& pixels);
    /// The string attributes stored in `file` whose names start with `prefix`.
    std::string (*read_attributes)(const std::string& file, const std::string& prefix,
                                   std::vector<std::pair<std::string, std::string>>& out);
    /// Reads the named uint32 channels; on failure `bad_channel` names the one at fault.
    std::string (*read_u32_channels)(const std::string& file, const std::vector<std::string>& names,
                                     int& width, int& height, std::vector<std::vector<uint32_t>>& out,
                                     std::string& bad_channel);
    /// Draws a laid-out plot into a PNG (lines, boxes, TrueType text). Without
    /// a usable font the PNG is written without text and `warning` says why.
    std::string (*draw_plot)(const std::string& file, const PlotDrawing& drawing, std::string& warning);
    /// Draws horizontal `texts` (no superscripts) over width x height linear RGB
    /// floats, at their own size, with the first usable of `fonts`. Without one
    /// the pixels stay as they are and `warning` says why.
    std::string (*draw_texts)(int width, int height, float* rgb, const std::vector<PlotText>& texts,
                              const std::vector<std::string>& fonts, std::string& warning);
};

inline constexpr int kImageCodecVersion = 3;
/// The plugin's one exported symbol: `extern "C" const ImageCodecApi* sahara_image_codec_api()`.
inline constexpr const char* kImageCodecSymbol = "sahara_image_codec_api";
/// The plugin's file name. It is looked for relative to the executable, never at
/// a path fixed at build time, so an installed or moved sahara finds its own copy:
/// beside the shared object the library is linked into (the Python module's
/// package directory), beside the executable (the build tree), then in the plugin directory of the
/// installed layout (lib/sahara beside bin by default; CMake compiles in the
/// relative path). set_image_codec_file (`sahara --image-codec FILE`) names the
/// file to load instead.
inline constexpr const char* kImageCodecLibrary = "libsahara_image_codec.so";

/// Makes `file` the only place the plugin is looked for (empty: the places
/// above again). Effective only before the codec is first needed: call it
/// before any image is read or written.
void set_image_codec_file(const std::string& file);

/// The outcome of looking for the plugin file (nothing is loaded).
struct ImageCodecSearch {
    std::string found;               ///< the file that would be loaded; empty: none exists
    std::vector<std::string> tried;  ///< every place looked at, in order
};
/// Looks for the plugin as image_codec() does, without loading it (sahara --version).
ImageCodecSearch find_image_codec();

/// The codec, loaded on the first call (thread-safe). Throws InputError naming
/// `file_for_errors` if the plugin cannot be found or loaded.
const ImageCodecApi& image_codec(const std::string& file_for_errors);

}  // namespace sahara
