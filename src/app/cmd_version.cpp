#include "app/cmd_version.h"

#include <omp.h>

#include <cstdio>
#include <string>
#include <vector>

#include "accel/simd_path.h"
#include "io/image_codec.h"

#if SAHARA_HAVE_EMBREE
#include <embree3/rtcore_config.h>
#endif
#if SAHARA_HAVE_MPI
#include <mpi.h>
#endif
#if SAHARA_HAVE_SDL2
#include <SDL.h>
#endif

namespace sahara {
namespace {

/// The OpenMP specification version the compiler implements (_OPENMP is its date).
std::string openmp_line() {
    struct Spec {
        long date;
        const char* version;
    };
    constexpr Spec kSpecs[] = {{202111, "5.2"}, {202011, "5.1"}, {201811, "5.0"}, {201511, "4.5"},
                               {201307, "4.0"}, {201107, "3.1"}, {200805, "3.0"}};
    std::string version = std::to_string(_OPENMP);
    for (const Spec& s : kSpecs)
        if (_OPENMP >= s.date) {
            version = s.version;
            break;
        }
    return version + ", " + std::to_string(omp_get_max_threads()) + " threads";
}

/// Every traversal build is compiled in (one translation unit per instruction
/// set); the CPU decides at run time which one runs.
std::string simd_line() {
    std::string line;
    for (SimdPath p : {SimdPath::sse2, SimdPath::avx2, SimdPath::avx512})
        line += std::string(simd_path_name(p)) + " ";
    line += "compiled in; this CPU runs ";
    line += simd_path_name(best_simd_path());
    if (active_simd_path() != best_simd_path())
        line += std::string(" (SAHARA_SIMD selects ") + simd_path_name(active_simd_path()) + ")";
    return line;
}

std::string embree_line() {
#if SAHARA_HAVE_EMBREE
    return RTC_VERSION_STRING " (the yardstick of sahara bench)";
#else
    return "no (built without Embree 3)";
#endif
}

std::string mpi_line() {
#if SAHARA_HAVE_MPI
    // Allowed before MPI_Init; the library's name and version end at the first comma.
    char text[MPI_MAX_LIBRARY_VERSION_STRING];
    int length = 0;
    if (MPI_Get_library_version(text, &length) != MPI_SUCCESS) return "yes";
    std::string name(text, size_t(length));
    name = name.substr(0, name.find_first_of(",\n"));
    return name + " (distributed rendering under mpirun)";
#else
    return "no (built without MPI)";
#endif
}

std::string sdl_line() {
#if SAHARA_HAVE_SDL2
    SDL_version v;
    SDL_GetVersion(&v);
    return std::to_string(v.major) + "." + std::to_string(v.minor) + "." + std::to_string(v.patch) +
           " (sahara render --preview)";
#else
    return "no (built without SDL2; no --preview)";
#endif
}

/// Found, not loaded: loading OpenImageIO would make --version take half a second.
std::string codec_line() {
#ifdef SAHARA_OIIO_VERSION
    std::string line = "OpenImageIO " SAHARA_OIIO_VERSION;
#else
    std::string line = "OpenImageIO";
#endif
    const ImageCodecSearch search = find_image_codec();
    if (!search.found.empty()) return line + ", plugin " + search.found;
    line += ", plugin not found (looked for ";
    for (size_t i = 0; i < search.tried.size(); ++i) line += (i ? ", " : "") + search.tried[i];
    return line + ")";
}

}  // namespace

std::string version_report() {
    const std::vector<std::pair<const char*, std::string>> parts = {
        {"OpenMP", openmp_line()}, {"SIMD", simd_line()}, {"Embree", embree_line()},
        {"MPI", mpi_line()},       {"SDL2", sdl_line()},  {"image codec", codec_line()},
    };
    std::string text = "sahara " SAHARA_VERSION "\n";
    for (const auto& [name, value] : parts) {
        char label[16];
        std::snprintf(label, sizeof label, "%-13s", (std::string(name) + ":").c_str());
        text += std::string("  ") + label + value + "\n";
    }
    return text;
}

int run_version_command() {
    std::fputs(version_report().c_str(), stdout);
    return 0;
}

}  // namespace sahara
