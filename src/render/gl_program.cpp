#include "render/gl_program.hpp"

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>

namespace arwb::render {
namespace {

unsigned compile(GLenum type, const char* text, const std::string& what, std::string* error) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &text, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    *error = what + " shader: " + log;
    glDeleteShader(s);
    return 0;
  }
  return s;
}

}  // namespace

unsigned link_program(const char* vertex, const char* fragment, const std::string& what, std::string* error) {
  const unsigned vs = compile(GL_VERTEX_SHADER, vertex, what, error);
  if (!vs) return 0;
  const unsigned fs = compile(GL_FRAGMENT_SHADER, fragment, what, error);
  if (!fs) {
    glDeleteShader(vs);
    return 0;
  }
  unsigned program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    *error = what + " shader: link failed: " + log;
    glDeleteProgram(program);
    program = 0;
  }
  return program;
}

}  // namespace arwb::render
