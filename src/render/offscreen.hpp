// An OpenGL 3.3 core context without a window or a display, for `arwb render` and tests: EGL on Mesa's
// surfaceless platform (llvmpipe when there is no GPU), so rendering works on a server with no X.
#pragma once

#include <string>

namespace arwb::render {

class OffscreenContext {
 public:
  OffscreenContext();   // creates the context and makes it current on this thread
  ~OffscreenContext();
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;
  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }   // why there is no context
  std::string renderer() const;                         // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"

 private:
  void* display_ = nullptr;
  void* context_ = nullptr;
  std::string error_;
};

}  // namespace arwb::render
