// The main of every test binary that links a target of ours: GoogleTest's, with the allocator set as arwb's main
// sets it (base/allocator.hpp), so that a test's images are allocated as the program's are.
#include "base/allocator.hpp"

#include <gtest/gtest.h>

int main(int argc, char** argv) {
  arwb::keep_freed_buffers();
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
