#include "io/obj_text.h"

#include <algorithm>
#include <string_view>

namespace sahara::obj {

namespace {

// Stands for a space inside a material name while tinyobjloader reads it: a
// control character no exporter writes into a name.
constexpr char kSpace = '\x1f';

bool is_blank(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
    while (!s.empty() && (is_blank(s.front()) || s.front() == '\r')) s.remove_prefix(1);
    while (!s.empty() && (is_blank(s.back()) || s.back() == '\r')) s.remove_suffix(1);
    return s;
}

/// True if `line` is `keyword` followed by a blank; `rest` is then what follows, trimmed.
bool rest_after(std::string_view line, std::string_view keyword, std::string_view& rest) {
    const std::string_view t = trim(line);
    if (t.size() <= keyword.size() || t.substr(0, keyword.size()) != keyword || !is_blank(t[keyword.size()]))
        return false;
    rest = trim(t.substr(keyword.size()));
    return true;
}

std::string encode_blanks(std::string_view name) {
    std::string out(name);
    for (char& c : out)
        if (is_blank(c)) c = kSpace;
    return out;
}

/// A data line (v, vt, vn, vp, f, l, p): a trailing `# comment` cut off, and in
/// face corners an empty trailing slot (`1/2/`, `1//`) dropped; tinyobjloader
/// refuses both.
bool is_data_line(std::string_view t) {
    const size_t end = t.find_first_of(" \t");
    const std::string_view key = t.substr(0, end);
    return end != std::string_view::npos && (key == "v" || key == "vt" || key == "vn" || key == "vp" ||
                                             key == "f" || key == "l" || key == "p");
}

std::string clean_data_line(std::string_view t) {
    if (const size_t hash = t.find('#'); hash != std::string_view::npos) t = trim(t.substr(0, hash));
    if (t.front() != 'f' && t.front() != 'l') return std::string(t);
    std::string out;
    size_t pos = 0;
    while (pos < t.size()) {  // word by word, blanks kept
        const size_t end = std::min(t.find_first_of(" \t", pos), t.size());
        std::string_view word = t.substr(pos, end - pos);
        while (word.size() > 1 && word.back() == '/') word.remove_suffix(1);
        out.append(word);
        if (end < t.size()) out.push_back(t[end]);
        pos = end + 1;
    }
    return out;
}

/// One logical line, rewritten where a name with spaces would be cut.
std::string prepare_obj_line(std::string_view line, const std::filesystem::path& dir) {
    if (is_data_line(trim(line))) return clean_data_line(trim(line));
    std::string_view rest;
    if (rest_after(line, "usemtl", rest) && rest.find_first_of(" \t") != std::string_view::npos)
        return "usemtl " + encode_blanks(rest);
    if (rest_after(line, "mtllib", rest) && rest.find(' ') != std::string_view::npos &&
        rest.find('\\') == std::string_view::npos) {
        std::error_code ec;
        if (std::filesystem::is_regular_file(dir / std::string(rest), ec)) {
            std::string escaped = "mtllib ";
            for (char c : rest) escaped += c == ' ' ? std::string("\\ ") : std::string(1, c);
            return escaped;
        }
    }
    return std::string(line);
}

}  // namespace

std::string prepare_obj_text(const std::string& text, const std::filesystem::path& dir) {
    std::string out;
    out.reserve(text.size());
    std::string logical;  // the current line, continuations joined
    int joined = 0;       // physical lines folded into it
    size_t pos = 0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        std::string_view line(text.data() + pos, end - pos);
        pos = end + 1;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        const bool comment = logical.empty() && !trim(line).empty() && trim(line).front() == '#';
        if (!comment && !line.empty() && line.back() == '\\' && pos < text.size()) {
            logical.append(line.substr(0, line.size() - 1)).push_back(' ');
            ++joined;
            continue;
        }
        logical.append(line);
        out += prepare_obj_line(logical, dir);
        out.append(size_t(joined) + 1, '\n');
        logical.clear();
        joined = 0;
    }
    return out;
}

std::string prepare_mtl_text(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    size_t pos = 0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        const bool last = end == std::string::npos;
        if (last) end = text.size();
        const std::string_view line(text.data() + pos, end - pos);
        pos = end + 1;
        std::string_view rest;
        if (rest_after(line, "newmtl", rest) && rest.find_first_of(" \t") != std::string_view::npos)
            out += "newmtl " + encode_blanks(rest);
        else
            out.append(line);
        if (!last) out.push_back('\n');
    }
    return out;
}

std::string decode_material_name(std::string name) {
    for (char& c : name)
        if (c == kSpace) c = ' ';
    return name;
}

}  // namespace sahara::obj
