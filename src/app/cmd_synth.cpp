#include "app/commands.hpp"
#include <cstdio>
namespace arwb {
int cmd_synth(int, char**) { std::fprintf(stderr, "arwb synth: not built yet\n"); return 2; }
}  // namespace arwb
