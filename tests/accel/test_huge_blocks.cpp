// HugeBlockReuse: huge-page blocks freed inside a scope serve the next requests that fit.
#include <doctest/doctest.h>

#include <cstring>
#include <vector>

#include "accel/bvh.h"

namespace sahara {

namespace {

constexpr size_t kMiB = size_t(1) << 20;

using HugeVector = std::vector<char, AlignedAllocator<char, 64>>;

}  // namespace

TEST_CASE("huge blocks: a block freed in a reuse scope serves the next request that fits") {
    const HugeBlockReuse reuse;
    HugeVector a(3 * kMiB, char(7));
    const char* first = a.data();
    a = HugeVector();
    const BuildArray<char> b(3 * kMiB - 4096);
    CHECK(b.get() == first);
    // The very memory, as it was left (a fresh block from the system would read zero).
    CHECK(b[0] == 7);
    CHECK(b[b.size() - 1] == 7);
}

TEST_CASE("huge blocks: a kept block more than a huge page larger than the request stays kept") {
    const HugeBlockReuse reuse;
    HugeVector big(8 * kMiB);
    const char* kept = big.data();
    big = HugeVector();
    const BuildArray<char> small(3 * kMiB);  // 4 MiB reserved: 8 would waste two huge pages
    CHECK(small.get() != kept);
    const BuildArray<char> fits(7 * kMiB);
    CHECK(fits.get() == kept);
}

TEST_CASE("huge blocks: a reused block comes back with its own size and not the last request's") {
    const HugeBlockReuse reuse;
    HugeVector block(6 * kMiB);
    const char* p = block.data();
    block = HugeVector();
    {
        const BuildArray<char> smaller(3 * kMiB + kMiB / 2);  // 4 MiB reserved, takes the 6 MiB block
        REQUIRE(smaller.get() == p);
    }
    const BuildArray<char> again(5 * kMiB + kMiB / 2);  // needs 6 MiB
    CHECK(again.get() == p);
}

TEST_CASE("huge blocks: the kept blocks are freed when the last scope ends") {
    {
        const HugeBlockReuse outer;
        {
            const HugeBlockReuse inner;
            HugeVector a(2 * kMiB);
        }
        void* kept = take_kept_huge_block(2 * kMiB);  // still kept: outer is alive
        REQUIRE(kept != nullptr);
        CHECK(keep_huge_block(kept, 2 * kMiB));
    }
    CHECK(take_kept_huge_block(2 * kMiB) == nullptr);
    HugeVector b(2 * kMiB);
    b = HugeVector();  // no scope: freed at once
    CHECK(take_kept_huge_block(2 * kMiB) == nullptr);
}

}  // namespace sahara
