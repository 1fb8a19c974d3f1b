#pragma once
/// Which way is up in a downloaded model. glTF says (+y, by the spec); an OBJ
/// does not, so `sahara view` applies the documented rule of docs/view.md:
/// the exporter named in the file's header comment, else the zero plane the
/// model stands on, else a ground or floor at its bottom, else a flat model's
/// thin axis, else +y.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "io/model_loader.h"

namespace sahara {

enum class UpAxis : uint8_t { x, y, z, neg_x, neg_y, neg_z };

/// The unit vector of the axis.
Vec3 up_vector(UpAxis a);
/// "+x", "-y", ...
const char* up_axis_name(UpAxis a);
/// "x", "+x", "-x", ... (none for anything else).
std::optional<UpAxis> parse_up_axis(std::string_view s);

struct UpAxisChoice {
    UpAxis axis = UpAxis::y;
    std::string reason;  ///< why, for the message on stderr
};

/// The up axis of an OBJ model (always +y or +z). `header` is the file's
/// leading comment block (see obj_header_comments).
UpAxisChoice guess_obj_up_axis(const LoadedModel& model, std::string_view header);

/// The comment lines at the top of an OBJ file (before its first statement),
/// where exporters name themselves. Empty if the file cannot be read.
std::string obj_header_comments(const std::filesystem::path& file);

}  // namespace sahara
