// The accelerator's capacity limits: a scene beyond what its structures index is
// refused with a message before any building, not built into wrong references.
#include <doctest/doctest.h>

#include <string>

#include "base/error.h"
#include "scene/accelerator.h"

using namespace sahara;

namespace {

/// The message check_accelerator_capacity throws, or "" when it accepts.
std::string capacity_error(size_t total, size_t largest_kind, BvhLayout layout) {
    try {
        check_accelerator_capacity(total, largest_kind, layout);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST_CASE("accelerator capacity: the wide tree's 2^26 leaf slots and 2^29 primitives per kind") {
    const size_t wide = size_t(1) << 26, per_kind = size_t(1) << 29;
    CHECK(capacity_error(wide, wide, BvhLayout::wide8).empty());
    CHECK(capacity_error(wide + 1, wide, BvhLayout::wide8) ==
          "scene too large: 67108865 primitives, more than the 67108864 that a wide BVH's leaf references "
          "reach (the pairs layout has none)");
    CHECK(capacity_error(wide + 1, wide + 1, BvhLayout::pairs).empty());
    CHECK(capacity_error(per_kind, per_kind, BvhLayout::pairs).empty());
    CHECK(capacity_error(per_kind + 1, per_kind + 1, BvhLayout::pairs) ==
          "scene too large: 536870913 primitives of one kind, more than the 536870912 that primitive ids "
          "index");
}
