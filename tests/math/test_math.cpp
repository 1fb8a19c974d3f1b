#include <doctest/doctest.h>

#include "math/transform.h"

using namespace sahara;

TEST_CASE("normals transform by the inverse transpose") {
    Mat4 m = Mat4::scale({2, 1, 1});
    Vec3 n = m.apply_normal(normalize(Vec3(1, 1, 0)));
    // The plane x + y = 0 scaled by 2 in x becomes x/2 + y = 0, normal (1, 2, 0)/sqrt5.
    CHECK(n.x == doctest::Approx(1 / std::sqrt(5.0f)));
    CHECK(n.y == doctest::Approx(2 / std::sqrt(5.0f)));
}
