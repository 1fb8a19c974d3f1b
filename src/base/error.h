#pragma once
/// Errors that the user can fix (bad input files, bad flags). The app turns
/// them into a one-line message and exit code 2; everything else is a bug.
#include <stdexcept>
#include <string>

namespace sahara {

/// Bad input: the message names the file, the element and what was expected,
/// e.g. "scene.json: objects[3].radius: expected a number > 0, got -1".
struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Builds "FILE: ELEMENT: WHAT" (ELEMENT may be empty).
inline InputError input_error(const std::string& file, const std::string& element, const std::string& what) {
    return InputError(element.empty() ? file + ": " + what : file + ": " + element + ": " + what);
}

}  // namespace sahara
