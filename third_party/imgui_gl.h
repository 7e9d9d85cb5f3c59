// Forced in front of Dear ImGui's OpenGL 3 backend (third_party/CMakeLists.txt), which is built with
// IMGUI_IMPL_OPENGL_LOADER_CUSTOM: it then calls OpenGL through the system headers and libGL (GLVND), as
// src/render does, instead of through its own gl3w loader. Debian's 1.86 loader (imgui_impl_opengl3_loader.h)
// stores 54 function pointers into a 53-entry array, undefined behaviour that UBSan stops at.
#pragma once
#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>
