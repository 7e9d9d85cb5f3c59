// The bundle's self-test run again in the page (export's is bundle/self_test.cpp): each id the scene maps drawn
// alone on a synthetic frame, found by the core's detector with the scene's dictionary and run through a fresh
// scene step over the page's media, each mapping judged as export judges it (script/self_test_verdict.hpp). So a
// phone says before its camera starts whether its core shows every marker's media, as the desktop did at export.
#pragma once

#include "media/media_provider.hpp"

#include <string>

namespace arwb::web {

// {"passed": bool, "error": "" or why the test could not run, "rows": [{"id", "line", "media", "detected", "fired",
// "detail"}]} for the scene at `scene_path` in the core's file system.
std::string self_test_json(const std::string& scene_path, media::MediaProvider& media);

}  // namespace arwb::web
