// How the C library's allocator keeps memory a program frees: image buffers (a frame, its grey image, the stages'
// images) are allocated and freed on every frame. By default glibc gives a block of more than 128 KiB back to the
// kernel when it is freed, and the next frame's block of the same size has its pages faulted in and zeroed again.
#pragma once

namespace arwb {

// Freed blocks of up to 32 MiB (a 3840x2160 colour frame) stay with the process for reuse, and the heap is not
// trimmed until a gigabyte is free at its top. Call first thing in main(); a no-op where the C library is not
// glibc, and under AddressSanitizer, whose allocator is its own.
void keep_freed_buffers();

}  // namespace arwb
