#include "app/commands.hpp"
#include <cstdio>
namespace arwb {
int cmd_bench(int, char**) { std::fprintf(stderr, "arwb bench: not built yet\n"); return 2; }
}  // namespace arwb
