#pragma once
/// Command-line arguments of `sahara render` (and `sahara view`), parsed by a
/// pure function so it can be tested directly.
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/cli_args.h"
#include "desc/scene_desc.h"

namespace sahara {

/// Render settings given on the command line; each overrides the scene's value.
struct RenderOverrides {
    std::optional<int> width, height, spp, max_depth;
    std::optional<uint64_t> seed;
    std::optional<IntegratorType> integrator;
    std::optional<double> time_limit_s, target_error;
    std::optional<float> exposure;
    std::optional<Tonemap> tonemap;
    std::optional<SamplerType> sampler;
    std::optional<BvhBuilder> bvh_builder;
    std::optional<BvhLayout> bvh_layout;
    std::optional<bool> packets;

    void apply(RenderSettings& r) const;
};

struct RenderArgs {
    std::optional<std::string> scene;  ///< none: the built-in default scene
    std::string output = "sahara.png";
    int threads = 0;
    bool quiet = false;
    bool stats = false;
    bool help = false;
    std::optional<double> checkpoint_s;       ///< --checkpoint: write the partial image this often
    std::optional<std::string> resume;        ///< --resume: continue the render stored in this EXR
    std::optional<std::string> reference;     ///< --reference: report the true error against this image
    bool auto_exposure = false;               ///< pick the exposure from the image (sahara view)
    bool preview = false;                     ///< --preview: live window
    std::optional<std::string> preview_dump;  ///< --preview-dump: write the window's last frame here
    RenderOverrides overrides;
    // --- sequences (distributed over MPI ranks when launched by mpirun) ---
    std::optional<std::pair<int, int>> frames;  ///< --frames A..B: render frames A to B (inclusive)
    std::optional<int> frame;                   ///< the frame this render is (set per frame, not a flag)
};

/// The output name of frame `frame`: the first run of '#' becomes the frame
/// number zero-padded to the run's length, or a printf-style %d / %0Nd is
/// replaced. Throws UsageError when `pattern` has neither.
std::string frame_output_name(const std::string& pattern, int frame);

/// Parses the arguments after `render` (the shared render flags through
/// add_render_flags). Throws UsageError.
RenderArgs parse_render_args(const std::vector<std::string>& args);
/// The same into `r`, whose values are the defaults; `extra` adds a command's
/// own options (those of `sahara view`).
void parse_render_args(const std::vector<std::string>& args, RenderArgs& r,
                       const std::function<void(CLI::App&)>& extra);

extern const char* const kRenderUsage;

}  // namespace sahara
