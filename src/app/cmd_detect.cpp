#include "app/commands.hpp"
#include <cstdio>
namespace arwb {
int cmd_detect(int, char**) { std::fprintf(stderr, "arwb detect: not built yet\n"); return 2; }
}  // namespace arwb
