#include "app/commands.hpp"
#include <cstdio>
namespace arwb {
int cmd_markers(int, char**) { std::fprintf(stderr, "arwb markers: not built yet\n"); return 2; }
}  // namespace arwb
