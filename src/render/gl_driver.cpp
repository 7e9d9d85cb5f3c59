#include "render/gl_driver.hpp"

#include <dlfcn.h>
#include <link.h>

#include <string>
#include <string_view>
#include <vector>

namespace arwb::render {
namespace {

// Mesa 22's drivers are dri/<name>_dri.so (one file under many names); later Mesa moves the code into
// libgallium-<version>.so, loaded by the same stubs.
bool is_mesa_driver(std::string_view path) {
  const size_t slash = path.rfind('/');
  const std::string_view name = slash == std::string_view::npos ? path : path.substr(slash + 1);
  return (name.size() > 7 && name.substr(name.size() - 7) == "_dri.so") || name.substr(0, 10) == "libgallium";
}

}  // namespace

int keep_gl_driver_loaded() {
  std::vector<std::string> drivers;
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* out) {
        if (info->dlpi_name && is_mesa_driver(info->dlpi_name))
          static_cast<std::vector<std::string>*>(out)->push_back(info->dlpi_name);
        return 0;
      },
      &drivers);
  int pinned = 0;
  // NOLOAD: only a driver already there; NODELETE: the unload that eglTerminate or glfwTerminate asks for waits
  // for exit. The handle only adds a reference, so it need not be kept.
  for (const auto& path : drivers)
    if (dlopen(path.c_str(), RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE)) ++pinned;
  return pinned;
}

}  // namespace arwb::render
