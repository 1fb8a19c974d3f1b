#pragma once
// The message of the InputError a piece of code throws, for tests of bad input.
#include <string>

#include "base/error.h"

namespace sahara::test {

/// What `f()` throws as InputError, or "(no InputError)" when it returns.
template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

}  // namespace sahara::test
