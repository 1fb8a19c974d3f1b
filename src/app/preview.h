#pragma once
/// The live preview window of `sahara render --preview` (SDL2). It is driven
/// from the main thread while the workers render: it copies only the tiles
/// that changed, at most 30 times a second and with a frame budget of ~2% of
/// one core, so it never holds the render back noticeably.
#include <filesystem>
#include <memory>
#include <string>

#include "render/film.h"
#include "render/renderer.h"
#include "desc/scene_desc.h"

namespace sahara {

class Preview {
   public:
    /// Opens a window for a width x height image. Returns nullptr after a
    /// one-line warning when no window can be shown (no display, no SDL2).
    static std::unique_ptr<Preview> open(int width, int height, float exposure, Tonemap curve);
    ~Preview();

    /// Handles window events and, when a frame is due, redraws the tiles that
    /// changed and the title (spp, elapsed, ETA). Call from RenderOptions::on_tick.
    void update(RenderSession& session);
    /// Draws the whole film (after the render) with a final title.
    void show_final(const Film& film, const std::string& title);
    /// Whether the user asked to stop (Esc or closing the window); clears the request.
    bool take_stop_request();
    /// Whether the user pressed S since the last call.
    bool take_snapshot_request();
    /// Writes the window's current contents as a binary PPM (P6).
    void dump(const std::filesystem::path& file) const;

    struct Impl;

   private:
    explicit Preview(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

/// Display bytes of one linear pixel exactly as an 8-bit output file stores it:
/// exposure, tone curve, sRGB encoding, rounding.
void display_bytes(const Rgb& linear, float exposure, Tonemap curve, unsigned char out[3]);

}  // namespace sahara
