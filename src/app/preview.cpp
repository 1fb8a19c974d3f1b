#include "app/preview.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <utility>
#include <vector>

#include "base/error.h"
#include "base/log.h"
#include "io/image_io.h"
#include "render/tonemap.h"

#if SAHARA_HAVE_SDL2
#include <SDL.h>
#endif

namespace sahara {

void display_bytes(const Rgb& linear, float exposure, Tonemap curve, unsigned char out[3]) {
    const float scale = std::exp2(exposure);
    for (int c = 0; c < 3; ++c) {
        const float v = tonemap_value(linear[c] * scale, curve);
        out[c] = (unsigned char)std::lround(std::clamp(srgb_encode(v), 0.0f, 1.0f) * 255.0f);
    }
}

#if SAHARA_HAVE_SDL2

using Clock = std::chrono::steady_clock;

namespace {

/// Frames never come faster than this, and each frame's cost is kept under
/// 1/kBudgetDivisor of the wall time between frames (5% of the main thread,
/// which shares the cores with the workers). The title is cheap and updates
/// at its own rate.
constexpr double kMinFrameSeconds = 1.0 / 30.0;
constexpr double kBudgetDivisor = 20.0;
constexpr double kTitleSeconds = 0.25;

std::string format_duration(double s) {
    char buf[32];
    if (s < 0) return "?";
    if (s < 100)
        std::snprintf(buf, sizeof buf, "%.1f s", s);
    else if (s < 6000)
        std::snprintf(buf, sizeof buf, "%d min %02d s", int(s) / 60, int(s) % 60);
    else
        std::snprintf(buf, sizeof buf, "%d h %02d min", int(s) / 3600, (int(s) / 60) % 60);
    return buf;
}

}  // namespace

struct Preview::Impl {
    SDL_Window* window = nullptr;
    SDL_Surface* image = nullptr;  ///< image-sized XRGB8888 buffer the tiles are drawn into
    int width = 0, height = 0;
    float exposure = 0;
    Tonemap curve = Tonemap::clamp;
    std::vector<uint64_t> seen;  ///< tile generations already drawn
    Clock::time_point next_frame = Clock::now(), next_title = Clock::now();
    bool stop = false, snapshot = false;

    ~Impl() {
        if (image) SDL_FreeSurface(image);
        if (window) SDL_DestroyWindow(window);
        SDL_QuitSubSystem(SDL_INIT_VIDEO);
    }

    void draw_pixel(const Film& film, int x, int y) {
        unsigned char b[3];
        display_bytes(film.mean(x, y), exposure, curve, b);
        auto* row = static_cast<uint32_t*>(image->pixels) + size_t(y) * size_t(image->pitch / 4);
        row[x] = SDL_MapRGB(image->format, b[0], b[1], b[2]);
    }

    void present() {
        SDL_Surface* target = SDL_GetWindowSurface(window);
        if (!target) return;
        if (target->w == image->w && target->h == image->h)
            SDL_BlitSurface(image, nullptr, target, nullptr);
        else
            SDL_BlitScaled(image, nullptr, target, nullptr);
        SDL_UpdateWindowSurface(window);
    }

    void set_title(const RenderSession& session) {
        char title[160];
        std::snprintf(title, sizeof title, "sahara - %d/%d spp%s - %s - ETA %s", session.spp_complete(),
                      session.spp_target(), session.pass_target() > 0 ? "" : " (adaptive)",
                      format_duration(session.elapsed_seconds()).c_str(),
                      format_duration(session.eta_seconds()).c_str());
        SDL_SetWindowTitle(window, title);
    }

    void poll_events() {
        SDL_Event e;
        while (SDL_PollEvent(&e)) {
            if (e.type == SDL_QUIT)
                stop = true;
            else if (e.type == SDL_WINDOWEVENT && e.window.event == SDL_WINDOWEVENT_CLOSE)
                stop = true;
            else if (e.type == SDL_WINDOWEVENT && e.window.event == SDL_WINDOWEVENT_EXPOSED)
                present();
            else if (e.type == SDL_KEYDOWN && e.key.keysym.sym == SDLK_ESCAPE)
                stop = true;
            else if (e.type == SDL_KEYDOWN && e.key.keysym.sym == SDLK_s)
                snapshot = true;
        }
    }
};

Preview::Preview(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Preview::~Preview() = default;

std::unique_ptr<Preview> Preview::open(int width, int height, float exposure, Tonemap curve) {
    const char* driver = std::getenv("SDL_VIDEODRIVER");
    if (!driver && !std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY")) {
        log_warning(
            "--preview: no display (DISPLAY and WAYLAND_DISPLAY are unset); rendering without a window");
        return nullptr;
    }
    // sahara's own SIGINT/SIGTERM handling (stop and save) must stay in charge.
    SDL_SetHint(SDL_HINT_NO_SIGNAL_HANDLERS, "1");
    if (SDL_InitSubSystem(SDL_INIT_VIDEO) != 0) {
        log_warning(std::string("--preview: cannot open a window (") + SDL_GetError() +
                    "); rendering without it");
        return nullptr;
    }
    auto impl = std::make_unique<Impl>();
    impl->width = width;
    impl->height = height;
    impl->exposure = exposure;
    impl->curve = curve;
    // Large images are shown scaled down to fit the screen.
    double scale = 1.0;
    SDL_Rect usable;
    if (SDL_GetDisplayUsableBounds(0, &usable) == 0 && usable.w > 0 && usable.h > 0)
        scale = std::min({1.0, 0.9 * usable.w / width, 0.9 * usable.h / height});
    const int ww = std::max(1, int(width * scale)), wh = std::max(1, int(height * scale));
    impl->window =
        SDL_CreateWindow("sahara", SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED, ww, wh, SDL_WINDOW_SHOWN);
    impl->image = impl->window
                      ? SDL_CreateRGBSurfaceWithFormat(0, width, height, 32, SDL_PIXELFORMAT_XRGB8888)
                      : nullptr;
    if (!impl->window || !impl->image) {
        log_warning(std::string("--preview: cannot open a window (") + SDL_GetError() +
                    "); rendering without it");
        return nullptr;
    }
    SDL_FillRect(impl->image, nullptr, SDL_MapRGB(impl->image->format, 0, 0, 0));
    impl->present();
    return std::unique_ptr<Preview>(new Preview(std::move(impl)));
}

void Preview::update(RenderSession& session) {
    Impl& p = *impl_;
    p.poll_events();
    const auto start = Clock::now();
    if (start >= p.next_title) {
        p.set_title(session);
        p.next_title =
            start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kTitleSeconds));
    }
    if (start < p.next_frame) return;
    const Film* film = nullptr;
    bool changed = false;
    session.visit_changed_tiles(p.seen, false, [&](const TileRect& r) {
        film = &session.film();
        for (int y = r.y0; y < r.y1; ++y)
            for (int x = r.x0; x < r.x1; ++x) p.draw_pixel(*film, x, y);
        changed = true;
    });
    if (changed) p.present();
    const double cost = std::chrono::duration<double>(Clock::now() - start).count();
    p.next_frame = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                               std::max(kMinFrameSeconds, kBudgetDivisor * cost)));
}

void Preview::show_final(const Film& film, const std::string& title) {
    Impl& p = *impl_;
    for (int y = 0; y < p.height; ++y)
        for (int x = 0; x < p.width; ++x) p.draw_pixel(film, x, y);
    SDL_SetWindowTitle(p.window, title.c_str());
    p.present();
    p.poll_events();
}

bool Preview::take_stop_request() { return std::exchange(impl_->stop, false); }
bool Preview::take_snapshot_request() { return std::exchange(impl_->snapshot, false); }

void Preview::dump(const std::filesystem::path& file) const {
    SDL_Surface* target = SDL_GetWindowSurface(impl_->window);
    SDL_Surface* rgb = target ? SDL_ConvertSurfaceFormat(target, SDL_PIXELFORMAT_RGB24, 0) : nullptr;
    if (!rgb) throw input_error(file.string(), "", std::string("cannot read the window: ") + SDL_GetError());
    std::ofstream out(file, std::ios::binary);
    out << "P6\n" << rgb->w << " " << rgb->h << "\n255\n";
    for (int y = 0; y < rgb->h; ++y)
        out.write(static_cast<const char*>(rgb->pixels) + size_t(y) * size_t(rgb->pitch),
                  std::streamsize(rgb->w) * 3);
    SDL_FreeSurface(rgb);
    if (!out) throw input_error(file.string(), "", "cannot write the preview dump");
}

#else  // no SDL2: the flag explains itself and the render runs headless

struct Preview::Impl {};
Preview::Preview(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Preview::~Preview() = default;
std::unique_ptr<Preview> Preview::open(int, int, float, Tonemap) {
    log_warning("--preview is not available: sahara was built without SDL2; rendering without a window");
    return nullptr;
}
void Preview::update(RenderSession&) {}
void Preview::show_final(const Film&, const std::string&) {}
bool Preview::take_stop_request() { return false; }
bool Preview::take_snapshot_request() { return false; }
void Preview::dump(const std::filesystem::path&) const {}

#endif

}  // namespace sahara
