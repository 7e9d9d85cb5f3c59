// Shader programs for the compositor's passes (media quads, meshes): compiled and linked in one call, the
// driver's log in the error. Needs a current OpenGL 3.3 core context.
#pragma once

#include <string>

namespace arwb::render {

// The linked program, or 0 with *error set ("<what> shader: 0:12(3): error: ...").
unsigned link_program(const char* vertex, const char* fragment, const std::string& what, std::string* error);

}  // namespace arwb::render
