// When the executable restarts itself under a passive OpenMP wait policy.
#include <doctest/doctest.h>

#include "app/omp_wait_policy.h"

using sahara::wants_passive_restart;

TEST_CASE("omp wait policy: restart only when the user chose no policy") {
    CHECK(wants_passive_restart(nullptr, nullptr, nullptr));
    CHECK(wants_passive_restart(nullptr, nullptr, "/usr/lib/libfoo.so"));
    // A policy of the user's (or of an earlier restart) is kept.
    CHECK_FALSE(wants_passive_restart("active", nullptr, nullptr));
    CHECK_FALSE(wants_passive_restart("passive", nullptr, nullptr));
    CHECK_FALSE(wants_passive_restart("", nullptr, nullptr));
    CHECK_FALSE(wants_passive_restart(nullptr, "10000", nullptr));
}

TEST_CASE("omp wait policy: no restart under valgrind") {
    CHECK_FALSE(
        wants_passive_restart(nullptr, nullptr, "/usr/libexec/valgrind/vgpreload_core-amd64-linux.so"));
}
