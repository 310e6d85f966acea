// Storage for a rank's image-size buffers (its parts of every pixel, the parts it receives, the chain's
// states): each is allocated once per run and written once, so the cost of its first touch is the
// kernel's, one page fault per page. On 4 KiB pages that is 24-26 ms for the 8.4 MB of a 256 x 256
// image's parts on one 2-core VM (about 3 ms per MB: a rank pays it whatever its share of the
// work; 3-6 ms on another); on 2 MiB transparent huge pages (madvise MADV_HUGEPAGE, which Debian's
// default "madvise" mode honours) 0.9-5 ms, but 12-17 ms when the kernel compacts memory to find the huge
// pages. Measured in docs/performance.md ("Two ranks against one", "volref-mpi on the
// resumable march"). The parts and the chain's arrays are
// made at set-up (main.cpp fresh_parts, Chain.h fresh_chain), outside render_s. Values are unaffected.
#pragma once
#include <sys/mman.h>

#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

namespace volref::mpi {

// std::allocator, except that a block of at least kHugePage bytes is aligned to kHugePage and, where the
// system has MADV_HUGEPAGE, advised onto transparent huge pages before its first touch.
template <class T>
struct HugePageAllocator {
    using value_type = T;
    static constexpr std::size_t kHugePage = std::size_t(1) << 21;
    HugePageAllocator() = default;
    template <class U>
    HugePageAllocator(const HugePageAllocator<U>&) {}
    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
        const std::size_t bytes = n * sizeof(T);
        if (bytes < kHugePage) return std::allocator<T>().allocate(n);
        const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
        void* p = std::aligned_alloc(kHugePage, rounded);
        if (!p) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
        madvise(p, rounded, MADV_HUGEPAGE);  // advice only: on failure the pages are ordinary ones
#endif
        return static_cast<T*>(p);
    }
    void deallocate(T* p, std::size_t n) {
        if (n * sizeof(T) < kHugePage) std::allocator<T>().deallocate(p, n);
        else std::free(p);
    }
    template <class U>
    bool operator==(const HugePageAllocator<U>&) const { return true; }
};

// A rank's parts of every pixel (Frame::slots() parts of kPart doubles each) and the other image-size
// arrays of doubles it fills once.
using PartBuffer = std::vector<double, HugePageAllocator<double>>;

}  // namespace volref::mpi
