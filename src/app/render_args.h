#pragma once
/// Command-line arguments of `sahara render` (and the shared render flags of
/// `sahara view`), parsed by a pure function so it can be tested directly.
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "desc/scene_desc.h"

namespace sahara {

/// A malformed command line: the app prints the message and the usage, exit 2.
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

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

/// Parses the arguments after `render`. Throws UsageError.
RenderArgs parse_render_args(const std::vector<std::string>& args);

/// Tries to consume one shared render flag at args[i] (advancing i past its
/// value). Returns false if args[i] is not such a flag. Throws UsageError.
bool parse_override_flag(const std::vector<std::string>& args, size_t& i, RenderOverrides& o);

/// Parses an integer/real flag value, throwing UsageError naming the flag.
long long parse_int_value(const std::string& flag, const std::string& value, long long lo, long long hi);
double parse_real_value(const std::string& flag, const std::string& value, double lo, double hi);
IntegratorType parse_integrator_name(const std::string& flag, const std::string& value);
SamplerType parse_sampler_name(const std::string& flag, const std::string& value);

extern const char* const kRenderUsage;

}  // namespace sahara
