// Embeds the viewer's files with the assembler's .incbin, so that simbot
// needs no file at run time to write a page. The paths (string literals)
// come from CMake (reports/CMakeLists.txt), which also rebuilds this file
// when one of them changes.
#include "reports/viewer_assets.h"

#define SIMBOT_INCBIN(name, path)                                                       \
  __asm__(                                                                              \
      ".section .rodata\n"                                                              \
      ".global simbot_asset_" #name                                                     \
      "\n"                                                                              \
      ".balign 16\n"                                                                    \
      "simbot_asset_" #name                                                             \
      ":\n"                                                                             \
      ".incbin \"" path                                                                 \
      "\"\n"                                                                            \
      ".global simbot_asset_" #name                                                     \
      "_end\n"                                                                          \
      "simbot_asset_" #name                                                             \
      "_end:\n"                                                                         \
      ".byte 0\n"                                                                       \
      ".previous\n");                                                                   \
  extern "C" const char simbot_asset_##name[];                                          \
  extern "C" const char simbot_asset_##name##_end[];                                    \
  std::string_view asset_##name() {                                                     \
    return {simbot_asset_##name,                                                        \
            static_cast<std::size_t>(simbot_asset_##name##_end - simbot_asset_##name)}; \
  }

namespace simbot::reports {
namespace {
SIMBOT_INCBIN(html, SIMBOT_VIEWER_DIR "/page.html")
SIMBOT_INCBIN(css, SIMBOT_VIEWER_DIR "/page.css")
SIMBOT_INCBIN(model, SIMBOT_VIEWER_DIR "/js/model.js")
SIMBOT_INCBIN(course, SIMBOT_VIEWER_DIR "/js/course.js")
SIMBOT_INCBIN(field2d, SIMBOT_VIEWER_DIR "/js/field2d.js")
SIMBOT_INCBIN(scene3d, SIMBOT_VIEWER_DIR "/js/scene3d.js")
SIMBOT_INCBIN(timeline, SIMBOT_VIEWER_DIR "/js/timeline.js")
SIMBOT_INCBIN(source, SIMBOT_VIEWER_DIR "/js/source.js")
SIMBOT_INCBIN(explain, SIMBOT_VIEWER_DIR "/js/explain.js")
SIMBOT_INCBIN(app, SIMBOT_VIEWER_DIR "/js/app.js")
SIMBOT_INCBIN(three, SIMBOT_THREE_JS)
SIMBOT_INCBIN(orbit, SIMBOT_ORBIT_JS)
}  // namespace

std::string_view viewerHtml() { return asset_html(); }
std::string_view viewerCss() { return asset_css(); }
std::vector<std::pair<std::string_view, std::string_view>> viewerScripts() {
  return {{"model.js", asset_model()},       {"course.js", asset_course()},
          {"field2d.js", asset_field2d()},   {"scene3d.js", asset_scene3d()},
          {"timeline.js", asset_timeline()}, {"source.js", asset_source()},
          {"explain.js", asset_explain()},   {"app.js", asset_app()}};
}
std::string_view threeJs() { return asset_three(); }
std::string_view orbitControlsJs() { return asset_orbit(); }

}  // namespace simbot::reports
