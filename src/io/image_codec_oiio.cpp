// The image codec plugin (see image_codec.h): OpenImageIO behind plain
// functions that return an error message instead of throwing.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <exception>
#include <memory>

#include "io/image_codec.h"

namespace sahara {
namespace {

namespace OIIO = OIIO_NAMESPACE;

OIIO::TypeDesc type_desc(ChannelType t) {
    switch (t) {
        case ChannelType::u8:
            return OIIO::TypeDesc::UINT8;
        case ChannelType::u32:
            return OIIO::TypeDesc::UINT32;
        default:
            return OIIO::TypeDesc::FLOAT;
    }
}

std::string decode(const std::string& name, const unsigned char* by_memory, size_t size, int max_side,
                   int max_channels, DecodedPixels& out) try {
    std::unique_ptr<OIIO::Filesystem::IOMemReader> proxy;
    std::unique_ptr<OIIO::ImageInput> in;
    if (by_memory) {
        proxy = std::make_unique<OIIO::Filesystem::IOMemReader>(by_memory, size);
        in = OIIO::ImageInput::open(name, nullptr, proxy.get());
    } else {
        in = OIIO::ImageInput::open(name);
    }
    if (!in) return "cannot decode image: " + OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) return "image has no pixels";
    if (spec.width > max_side || spec.height > max_side)
        return "image size " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
               " is outside 1.." + std::to_string(max_side) + " per side";
    out.width = spec.width;
    out.height = spec.height;
    out.channels = std::min(spec.nchannels, max_channels);
    out.alpha_channel = spec.alpha_channel < out.channels ? spec.alpha_channel : -1;
    out.values.assign(size_t(spec.width) * size_t(spec.height) * size_t(out.channels), 0.0f);
    if (!in->read_image(0, 0, 0, out.channels, OIIO::TypeDesc::FLOAT, out.values.data()))
        return "cannot decode image: " + in->geterror();
    in->close();
    return "";
} catch (const std::exception& e) {
    return std::string("cannot decode image: ") + e.what();
}

std::string encode(const std::string& file, const PixelsToWrite& p) try {
    const bool bytes = !p.types.empty() && p.types[0] == ChannelType::u8;
    OIIO::ImageSpec spec(p.width, p.height, int(p.types.size()),
                         bytes ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
    bool mixed = false;
    for (ChannelType t : p.types) mixed |= t != p.types[0];
    if (mixed) {
        spec.channelformats.clear();
        for (ChannelType t : p.types) spec.channelformats.push_back(type_desc(t));
    }
    for (size_t c = 0; c < p.names.size() && c < p.types.size(); ++c) spec.channelnames[c] = p.names[c];
    for (const auto& [key, value] : p.attributes) spec.attribute(key, value);
    if (p.srgb) spec.attribute("oiio:ColorSpace", "sRGB");
    if (p.lossless_zip) spec.attribute("compression", "zip");
    auto out = OIIO::ImageOutput::create(file);
    if (!out) return "cannot create image writer: " + OIIO::geterror();
    const OIIO::TypeDesc format = mixed ? OIIO::TypeDesc::UNKNOWN : type_desc(p.types[0]);
    if (!(out->open(file, spec) && out->write_image(format, p.data) && out->close()))
        return "cannot write image: " + out->geterror();
    return "";
} catch (const std::exception& e) {
    return std::string("cannot write image: ") + e.what();
}

std::string read_attributes(const std::string& file, const std::string& prefix,
                            std::vector<std::pair<std::string, std::string>>& out) try {
    auto in = OIIO::ImageInput::open(file);
    if (!in) return "cannot open image: " + OIIO::geterror();
    for (const OIIO::ParamValue& p : in->spec().extra_attribs) {
        const std::string key = p.name().string();
        if (key.rfind(prefix, 0) == 0) out.emplace_back(key, p.get_string());
    }
    return "";
} catch (const std::exception& e) {
    return std::string("cannot open image: ") + e.what();
}

std::string read_u32_channels(const std::string& file, const std::vector<std::string>& names, int& width,
                              int& height, std::vector<std::vector<uint32_t>>& out,
                              std::string& bad_channel) try {
    auto in = OIIO::ImageInput::open(file);
    if (!in) return "cannot open image: " + OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    width = spec.width;
    height = spec.height;
    for (const std::string& channel : names) {
        bad_channel = channel;
        const auto it = std::find(spec.channelnames.begin(), spec.channelnames.end(), channel);
        if (it == spec.channelnames.end()) return "channel missing";
        const int c = int(it - spec.channelnames.begin());
        if (spec.channelformat(c) != OIIO::TypeDesc::UINT32) return "expected uint32 data";
        std::vector<uint32_t> values(size_t(spec.width) * size_t(spec.height));
        if (!in->read_image(0, 0, c, c + 1, OIIO::TypeDesc::UINT32, values.data()))
            return "cannot read: " + in->geterror();
        out.push_back(std::move(values));
    }
    bad_channel.clear();
    return "";
} catch (const std::exception& e) {
    return std::string("cannot read image: ") + e.what();
}

constexpr ImageCodecApi kApi{kImageCodecVersion, decode, encode, read_attributes, read_u32_channels};

}  // namespace
}  // namespace sahara

extern "C" __attribute__((visibility("default"))) const sahara::ImageCodecApi* sahara_image_codec_api() {
    return &sahara::kApi;
}
