// The C functions the page's worker calls (Module.cwrap): one WebDetector and one WebScene per module instance,
// strings in and out as UTF-8. Thin on purpose: everything they do is WebDetector's and WebScene's.
#include "web_detector.hpp"
#include "web_scene.hpp"

#include <emscripten/emscripten.h>

namespace {
arwb::web::WebDetector& detector() {
  static arwb::web::WebDetector d;
  return d;
}
arwb::web::WebScene& scene() {
  static arwb::web::WebScene s;
  return s;
}
thread_local std::string g_message;
}  // namespace

extern "C" {

// Empty string on success, else the message.
EMSCRIPTEN_KEEPALIVE const char* arwb_set_dictionaries(const char* list) {
  g_message = detector().set_dictionaries(list ? list : "");
  return g_message.c_str();
}

EMSCRIPTEN_KEEPALIVE const char* arwb_set_param(const char* name, double value) {
  g_message = detector().set_param(name ? name : "", value);
  return g_message.c_str();
}

// The camera for poses: a calibration file's path in the module's file system ("" for the default camera), and the
// markers' side (0: no poses).
EMSCRIPTEN_KEEPALIVE const char* arwb_set_camera(const char* path, double marker_side) {
  g_message = detector().set_camera(path ? path : "", marker_side);
  return g_message.c_str();
}

// Where to write width * height * 4 bytes of RGBA; null for a size out of 1..8192.
EMSCRIPTEN_KEEPALIVE uint8_t* arwb_frame(int width, int height) { return detector().frame(width, height); }

EMSCRIPTEN_KEEPALIVE const char* arwb_detect() { return detector().detect().c_str(); }

// The scene file to run on the detections (a path in the module's file system); its status as JSON.
EMSCRIPTEN_KEEPALIVE const char* arwb_scene_load(const char* path) {
  g_message = scene().load(path ? path : "");
  return g_message.c_str();
}

// A video's size and length as the page read them (the core decodes no video).
EMSCRIPTEN_KEEPALIVE void arwb_scene_video(const char* path, int width, int height, double duration_s) {
  scene().set_video(path ? path : "", width, height, duration_s);
}

// The tracker and the scene on the last detect()'s markers, at `t_s` seconds; the overlays as JSON.
EMSCRIPTEN_KEEPALIVE const char* arwb_scene_step(double t_s) { return scene().step(detector(), t_s).c_str(); }

// A mesh a step named, its parts' arrays as addresses in the module's memory (valid until the next call).
EMSCRIPTEN_KEEPALIVE const char* arwb_scene_mesh(int id) { return scene().mesh(id).c_str(); }

// The bundle's self-test on the scene file at `path`, beside the running scene; its rows as JSON.
EMSCRIPTEN_KEEPALIVE const char* arwb_scene_self_test(const char* path) {
  g_message = scene().self_test(path ? path : "");
  return g_message.c_str();
}

}
