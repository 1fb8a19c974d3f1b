#pragma once
/// Lists in messages and reports ("a, b, c").
#include <string>
#include <vector>

namespace sahara {

/// The items in order with `separator` between them ("" when there are none).
inline std::string join(const std::vector<std::string>& items, const char* separator = ", ") {
    std::string out;
    for (const std::string& item : items) out.append(out.empty() ? "" : separator).append(item);
    return out;
}

}  // namespace sahara
