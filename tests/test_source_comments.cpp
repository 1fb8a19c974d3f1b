// Source comments say why the code is as it is. Timings, dated benchmark runs and
// commit references go stale with the next change, so they belong in
// docs/performance.md; these tests keep them out of src/. Plain string scanning,
// not <regex>: GCC 12 warns inside std::regex under the sanitizer build.
#include <doctest/doctest.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace fs = std::filesystem;

namespace {

bool is_digit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }
bool is_word_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_'; }
bool is_lower_hex(char c) { return is_digit(c) || (c >= 'a' && c <= 'f'); }

/// The index just past the character or string literal whose opening quote is line[i].
size_t skip_literal(const std::string& line, size_t i) {
    const char quote = line[i++];
    while (i < line.size() && line[i] != quote) i += line[i] == '\\' ? 2 : 1;
    return i + 1;
}

/// Whether line[i] opens a literal (a quote right after a digit is a digit separator).
bool opens_literal(const std::string& line, size_t i) {
    return line[i] == '"' || (line[i] == '\'' && (i == 0 || !is_digit(line[i - 1])));
}

/// The comment text of every line of a C++ source, code and literals left out, so
/// that the checks see only what comments say (hex constants in code are no hashes).
std::vector<std::string> comment_text_by_line(std::istream& in) {
    std::vector<std::string> comments;
    bool in_block = false;
    std::string line;
    while (std::getline(in, line)) {
        std::string text;
        for (size_t i = 0; i < line.size();) {
            if (in_block) {
                in_block = line.compare(i, 2, "*/") != 0;
                text += in_block ? line[i] : ' ';
                i += in_block ? 1 : 2;
            } else if (line.compare(i, 2, "//") == 0) {
                text += line.substr(i + 2);
                break;
            } else if (line.compare(i, 2, "/*") == 0) {
                in_block = true;
                i += 2;
            } else {
                i = opens_literal(line, i) ? skip_literal(line, i) : i + 1;
            }
        }
        comments.push_back(text);
    }
    return comments;
}

/// Whether the whole word `w` starts at text[i].
bool word_at(const std::string& text, size_t i, std::string_view w) {
    return i <= text.size() && text.compare(i, w.size(), w) == 0 && (i == 0 || !is_word_char(text[i - 1])) &&
           (i + w.size() >= text.size() || !is_word_char(text[i + w.size()]));
}

size_t skip_spaces(const std::string& text, size_t i) {
    while (i < text.size() && text[i] == ' ') ++i;
    return i;
}

/// The index past a number ("3", "1.5") at text[i]; i when there is none.
size_t skip_number(const std::string& text, size_t i) {
    if (i >= text.size() || !is_digit(text[i])) return i;
    while (i < text.size() && (is_digit(text[i]) || text[i] == '.')) ++i;
    return i;
}

/// The index past a percentage or range of them ("3%", "+1.5 - 3 %") at text[i];
/// i when there is none.
size_t skip_percent(const std::string& text, size_t i) {
    size_t j = i < text.size() && (text[i] == '+' || text[i] == '-') ? i + 1 : i;
    const size_t number_end = skip_number(text, j);
    if (number_end == j) return i;
    j = skip_spaces(text, number_end);
    if (j < text.size() && text[j] == '-') j = skip_spaces(text, skip_number(text, skip_spaces(text, j + 1)));
    return j < text.size() && text[j] == '%' ? j + 1 : i;
}

/// "3% faster", "1.5-3% slower", "2% better" (`lower`: the comment in lower case).
bool has_percent_comparison(const std::string& lower) {
    for (size_t i = 1; i < lower.size(); ++i) {
        if (lower[i] != '%' || !is_digit(lower[i - 1])) continue;
        const size_t w = skip_spaces(lower, i + 1);
        for (std::string_view word : {"faster", "slower", "quicker", "better", "worse"})
            if (word_at(lower, w, word)) return true;
    }
    return false;
}

/// `word` followed by what `follows` accepts at the next non-space: "faster by",
/// "gained 4-18%".
template <class Follows>
bool has_word_followed_by(const std::string& lower, std::string_view word, Follows follows) {
    for (size_t i = lower.find(word); i != std::string::npos; i = lower.find(word, i + 1))
        if (word_at(lower, i, word) && follows(skip_spaces(lower, i + word.size()))) return true;
    return false;
}

/// "faster by a third", "shadow rays gained 4-18%", "lost +2%".
bool has_speed_phrase(const std::string& lower) {
    auto by = [&](size_t j) { return word_at(lower, j, "by"); };
    auto percent = [&](size_t j) { return skip_percent(lower, j) != j; };
    for (std::string_view word : {"faster", "slower"})
        if (has_word_followed_by(lower, word, by)) return true;
    for (std::string_view word : {"gain", "gains", "gained", "lost", "loses"})
        if (has_word_followed_by(lower, word, percent)) return true;
    return false;
}

/// A 20xx-xx-xx date ("2026-11-22").
bool has_date(const std::string& text) {
    constexpr std::string_view kShape = "20dd-md-Dd";  // d: digit, m: 0 or 1, D: 0 to 3
    for (size_t i = 0; i + kShape.size() <= text.size(); ++i) {
        bool match = (i == 0 || !is_word_char(text[i - 1])) &&
                     (i + kShape.size() == text.size() || !is_word_char(text[i + kShape.size()]));
        for (size_t k = 0; match && k < kShape.size(); ++k) {
            const char c = text[i + k], s = kShape[k];
            match = s == 'd'   ? is_digit(c)
                    : s == 'm' ? (c == '0' || c == '1')
                    : s == 'D' ? (c >= '0' && c <= '3')
                               : c == s;
        }
        if (match) return true;
    }
    return false;
}

/// Whether `text` names a commit: a word of 7-40 lowercase hex digits with at least
/// one digit and one letter (so neither a number nor a word like "defaced").
bool has_commit_hash(const std::string& text) {
    for (size_t i = 0; i < text.size();) {
        if (!is_word_char(text[i])) {
            ++i;
            continue;
        }
        size_t end = i;
        bool hex = true, digit = false, letter = false;
        for (; end < text.size() && is_word_char(text[end]); ++end) {
            hex &= is_lower_hex(text[end]);
            digit |= is_digit(text[end]);
            letter |= text[end] >= 'a' && text[end] <= 'f';
        }
        if (hex && digit && letter && end - i >= 7 && end - i <= 40) return true;
        i = end;
    }
    return false;
}

/// Why a comment is a measurement diary, or empty when it is not.
std::string diary_reason(const std::string& comment) {
    std::string lower = comment;
    for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (has_percent_comparison(lower) || has_speed_phrase(lower)) return "speed change (N% faster/slower)";
    if (has_date(comment)) return "dated measurement (20xx-xx-xx)";
    if (has_commit_hash(comment)) return "commit hash";
    return {};
}

std::string first_diary_reason(const std::string& source) {
    std::istringstream in(source);
    for (const std::string& comment : comment_text_by_line(in))
        if (std::string reason = diary_reason(comment); !reason.empty()) return reason;
    return {};
}

bool is_source_file(const fs::path& p) {
    const std::string ext = p.extension().string();
    return ext == ".h" || ext == ".cpp" || ext == ".inl" || ext == ".inc";
}

}  // namespace

TEST_CASE("source comments: the diary checks flag measurements and pass explanations") {
    CHECK(first_diary_reason("// (diffuse rays 1.5-3% faster on the AVX-512 step)\n") != "");
    CHECK(first_diary_reason("int x;  // shadow rays were 14-18% slower with it\n") != "");
    CHECK(first_diary_reason("/// 0.3% worse (bunny) and 2.0 % Better (ogre)\n") != "");
    CHECK(first_diary_reason("/// a one-time cost, faster by a third\n") != "");
    CHECK(first_diary_reason("/// shadow rays gained 4-18% on the bunny and lost 8 - 10 % on suzanne\n") !=
          "");
    CHECK(first_diary_reason("/// lost +2%\n") != "");
    CHECK(first_diary_reason("/// Measured 2026-11-22 on this shared 2-core VM\n") != "");
    CHECK(first_diary_reason("// same speed as at 4361f92\n") != "");
    CHECK(first_diary_reason("/* vs ddb9b16d0e1f:\n   the old layout */\n") != "");
    CHECK(first_diary_reason("/* the old layout,\n   before ddb9b16 */ int x;\n") != "");

    CHECK(first_diary_reason("/// 16 bins: SAH within 1% of 64\n") == "");
    CHECK(first_diary_reason("/// the NaN (0xFFC00000) is above them all\n") == "");
    CHECK(first_diary_reason("/// 1234567 rays, a defaced word, mask 0xffc00000\n") == "");
    CHECK(first_diary_reason("/// 5% of the main thread, a frame budget of ~2%\n") == "");
    CHECK(first_diary_reason("/// Narkowicz's 2015 fit (JCGT 2013), 2020-ish, 20261122\n") == "");
    CHECK(first_diary_reason("/// the gain of 1.0, faster than a branch, slower bytes\n") == "");
    // Code and string literals are not comments.
    CHECK(first_diary_reason("const uint64_t k = 0x9e3779b97f4a7c15;  // golden ratio\n") == "");
    CHECK(first_diary_reason("printf(\"3% faster // 2026-11-22\");\n") == "");
    CHECK(first_diary_reason("char q = '\"'; int n = 1'000'000;  // a quote\n") == "");
}

TEST_CASE("source comments: no measurement diary under src/") {
    const fs::path root = fs::path(SAHARA_SOURCE_DIR);
    int files = 0;
    for (const auto& entry : fs::recursive_directory_iterator(root / "src")) {
        if (!entry.is_regular_file() || !is_source_file(entry.path())) continue;
        ++files;
        std::ifstream in(entry.path());
        REQUIRE(in);
        const std::vector<std::string> comments = comment_text_by_line(in);
        for (size_t i = 0; i < comments.size(); ++i) {
            const std::string reason = diary_reason(comments[i]);
            if (!reason.empty())
                FAIL_CHECK(entry.path().lexically_relative(root).string()
                           << ":" << i + 1 << ": " << reason
                           << " in a comment (measurements belong in docs/performance.md):\n    //"
                           << comments[i]);
        }
    }
    CHECK(files > 0);
}
