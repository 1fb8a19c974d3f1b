#include <sys/mman.h>

#include <cstdint>
#include <mutex>
#include <new>
#include <vector>

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

namespace {

struct Block {
    void* p;
    size_t bytes;  ///< what was reserved for it (whole huge pages)
};

/// The blocks kept by the live HugeBlockReuse scopes, and those handed out again (whose
/// reserved size the new owner's request no longer tells).
struct KeptBlocks {
    std::mutex mutex;
    int scopes = 0;
    std::vector<Block> kept, lent;
};

KeptBlocks& kept_blocks() {
    static KeptBlocks k;
    return k;
}

}  // namespace

HugeBlockReuse::HugeBlockReuse() {
    KeptBlocks& k = kept_blocks();
    const std::lock_guard lock(k.mutex);
    ++k.scopes;
}

HugeBlockReuse::~HugeBlockReuse() {
    KeptBlocks& k = kept_blocks();
    const std::lock_guard lock(k.mutex);
    if (--k.scopes > 0) return;
    for (const Block& b : k.kept) ::operator delete(b.p, std::align_val_t(kHugePageBytes));
    k.kept.clear();
    k.lent.clear();  // their owners free them with operator delete from now on
}

void* take_kept_huge_block(size_t bytes) {
    KeptBlocks& k = kept_blocks();
    const std::lock_guard lock(k.mutex);
    // The smallest that fits, at most one huge page too big: the new owner may keep it
    // (leaf blocks) and would hold the rest unused.
    size_t best = k.kept.size();
    for (size_t i = 0; i < k.kept.size(); ++i)
        if (k.kept[i].bytes >= bytes && k.kept[i].bytes <= bytes + kHugePageBytes &&
            (best == k.kept.size() || k.kept[i].bytes < k.kept[best].bytes))
            best = i;
    if (best == k.kept.size()) return nullptr;
    const Block b = k.kept[best];
    k.kept.erase(k.kept.begin() + std::ptrdiff_t(best));
    k.lent.push_back(b);
    return b.p;
}

bool keep_huge_block(void* p, size_t bytes) {
    KeptBlocks& k = kept_blocks();
    const std::lock_guard lock(k.mutex);
    if (k.scopes == 0) return false;
    Block b{p, bytes};
    for (size_t i = 0; i < k.lent.size(); ++i)
        if (k.lent[i].p == p) {
            b = k.lent[i];
            k.lent.erase(k.lent.begin() + std::ptrdiff_t(i));
            break;
        }
    k.kept.push_back(b);
    return true;
}

}  // namespace sahara
