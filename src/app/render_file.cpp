#include "app/render_file.h"

#include <cstring>

#include "base/error.h"
#include "io/files.h"
#include "io/plot.h"
#include "math/rng.h"
#include "pipeline/render_pipeline.h"

namespace sahara {

namespace {

const char* integrator_name(IntegratorType t) {
    switch (t) {
        case IntegratorType::path:
            return "path";
        case IntegratorType::whitted:
            return "whitted";
        case IntegratorType::albedo:
            return "albedo";
        case IntegratorType::normals:
            return "normals";
        case IntegratorType::depth:
            return "depth";
        case IntegratorType::bvh_cost:
            return "bvh-cost";
    }
    return "?";
}

/// State channel names; a double is stored as its high and low 32 bits.
const char* const kStateChannels[] = {
    "sahara_state.sum_r_hi", "sahara_state.sum_r_lo", "sahara_state.sum_g_hi",
    "sahara_state.sum_g_lo", "sahara_state.sum_b_hi", "sahara_state.sum_b_lo",
    "sahara_state.sumsq_hi", "sahara_state.sumsq_lo", "sahara_state.count"};
constexpr size_t kStateChannelCount = sizeof(kStateChannels) / sizeof(kStateChannels[0]);

uint64_t bits_of(double v) {
    uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
}

double double_of(uint32_t hi, uint32_t lo) {
    const uint64_t b = (uint64_t(hi) << 32) | lo;
    double v;
    std::memcpy(&v, &b, sizeof v);
    return v;
}

std::vector<ExtraChannel> state_channels(const Film& film) {
    const size_t n = size_t(film.width()) * size_t(film.height());
    std::vector<ExtraChannel> ch(kStateChannelCount);
    for (size_t c = 0; c < kStateChannelCount; ++c) ch[c] = {kStateChannels[c], std::vector<uint32_t>(n)};
    for (int y = 0; y < film.height(); ++y)
        for (int x = 0; x < film.width(); ++x) {
            const size_t i = size_t(y) * size_t(film.width()) + size_t(x);
            const Vec3d& s = film.sum(x, y);
            const uint64_t words[4] = {bits_of(s.x), bits_of(s.y), bits_of(s.z), bits_of(film.sum_sq(x, y))};
            for (size_t k = 0; k < 4; ++k) {
                ch[2 * k].values[i] = uint32_t(words[k] >> 32);
                ch[2 * k + 1].values[i] = uint32_t(words[k]);
            }
            ch[8].values[i] = film.count(x, y);
        }
    return ch;
}

const std::string* find_key(const ImageMetadata& meta, const std::string& key) {
    for (const auto& [k, v] : meta)
        if (k == key) return &v;
    return nullptr;
}

}  // namespace

const char* stop_reason_name(StopReason r) {
    switch (r) {
        case StopReason::complete:
            return "complete";
        case StopReason::converged:
            return "converged";
        case StopReason::time_limit:
            return "time limit";
        case StopReason::interrupted:
            return "interrupted";
    }
    return "?";
}

std::string scene_fingerprint(const std::string& source) {
    std::string bytes;
    try {
        bytes = read_file(source);
    } catch (const InputError&) {
        return "-";  // the built-in scene, or a file gone since it was parsed
    }
    uint64_t h = hash_words(bytes.size(), 0x5a4a);
    for (size_t i = 0; i < bytes.size(); i += 8) {
        uint64_t word = 0;
        std::memcpy(&word, bytes.data() + i, std::min<size_t>(8, bytes.size() - i));
        h = hash_words(h, word);
    }
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    return hex;
}

ImageMetadata render_identity(const Scene& scene) {
    const RenderSettings& r = scene.render;
    return {{"scene", scene.source},
            {"scene_hash", scene_fingerprint(scene.source)},
            {"seed", std::to_string(r.seed)},
            {"resolution", std::to_string(r.width) + "x" + std::to_string(r.height)},
            {"max_depth", std::to_string(r.max_depth)},
            {"integrator", integrator_name(r.integrator)}};
}

ImageMetadata render_metadata(const Scene& scene, const Film& film, const RenderResult& result,
                              double total_render_seconds) {
    ImageMetadata m = render_identity(scene);
    m.emplace_back("spp", std::to_string(result.spp_done));
    m.emplace_back("spp_requested", std::to_string(scene.render.spp));
    m.emplace_back("spp_mean", std::to_string(result.spp_mean));
    m.emplace_back("render_seconds", std::to_string(total_render_seconds));
    m.emplace_back("nonfinite_samples", std::to_string(film.nonfinite_samples()));
    m.emplace_back("status", stop_reason_name(result.stop));
    m.emplace_back("version", SAHARA_VERSION);
    return m;
}

size_t write_render(const std::filesystem::path& file, const Scene& scene, const Film& film,
                    const ImageMetadata& metadata, std::optional<float> exposure) {
    const bool hdr = is_hdr_output(file);
    return write_rgb_image(file, film.width(), film.height(), film.to_rgb(),
                           exposure.value_or(scene.render.exposure), scene.render.tonemap, metadata,
                           hdr ? state_channels(film) : std::vector<ExtraChannel>{});
}

double resume_film(const std::filesystem::path& file, const Scene& scene, Film& film) {
    const std::string name = file.string();
    const ImageMetadata meta = read_image_metadata(file);
    if (!find_key(meta, "version"))
        throw input_error(name, "", "not an image written by sahara (no sahara metadata)");
    for (const auto& [key, want] : render_identity(scene)) {
        const std::string* have = find_key(meta, key);
        if (!have || *have != want)
            throw input_error(name, key,
                              "cannot resume: the file was rendered with " +
                                  (have ? *have : std::string("(none)")) + ", this render uses " + want);
    }
    std::vector<std::string> names(kStateChannels, kStateChannels + kStateChannelCount);
    int w = 0, h = 0;
    const std::vector<ExtraChannel> ch = read_extra_channels(file, names, &w, &h);
    if (w != film.width() || h != film.height())
        throw input_error(name, "", "image size differs from the render");
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            const Vec3d sum(double_of(ch[0].values[i], ch[1].values[i]),
                            double_of(ch[2].values[i], ch[3].values[i]),
                            double_of(ch[4].values[i], ch[5].values[i]));
            film.set_pixel_state(x, y, sum, double_of(ch[6].values[i], ch[7].values[i]), ch[8].values[i]);
        }
    if (const std::string* nf = find_key(meta, "nonfinite_samples")) film.add_nonfinite(std::stoull(*nf));
    const std::string* secs = find_key(meta, "render_seconds");
    return secs ? std::atof(secs->c_str()) : 0.0;
}

std::string draw_bvh_cost_legend(BvhCostImage& image, const std::filesystem::path& file) {
    std::vector<PlotText> texts;
    for (const LegendLabel& label : image.labels) {
        PlotText t;
        t.role = "legend";
        t.text = label.text;
        t.at = {double(label.x), double(label.y)};
        t.size = label.size;
        t.color = {0, 0, 0};
        t.anchor = label.right_aligned ? TextAnchor::end : TextAnchor::start;
        t.baseline = TextBaseline::hanging;
        texts.push_back(t);
    }
    return draw_texts(image.width, image.height, image.rgb, texts, file.string());
}

}  // namespace sahara
