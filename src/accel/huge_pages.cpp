#include <sys/mman.h>

#include <cstdint>

#include "accel/bvh.h"

namespace sahara {

void advise_huge_pages(void* p, size_t bytes) {
#ifdef MADV_HUGEPAGE
    // madvise wants a page-aligned start; allocations this big are 2 MiB aligned.
    const auto start = reinterpret_cast<uintptr_t>(p);
    if (start % kHugePageBytes == 0) madvise(p, bytes, MADV_HUGEPAGE);
#else
    (void)p, (void)bytes;
#endif
}

}  // namespace sahara
