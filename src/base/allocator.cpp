#include "base/allocator.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace arwb {

void keep_freed_buffers() {
#if defined(__GLIBC__)
  // 32 MiB is the largest threshold glibc accepts on 64-bit. Setting it also stops glibc's own adjustment, which
  // raises the threshold only after a large block has been freed to the kernel once.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

}  // namespace arwb
