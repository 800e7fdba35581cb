// The viewer's files, compiled into simbot (reports/viewer_assets.cpp): the
// page template and style (reports/viewer/page.*), its script in parts
// (reports/viewer/js/*.js, in the order they must run), and three.js with its
// orbit controls from Debian's libjs-three.
// Private to reports/.
#pragma once
#include <string_view>
#include <utility>
#include <vector>

namespace simbot::reports {

std::string_view viewerHtml();
std::string_view viewerCss();
// (file name, text) of each part of the viewer's script, in order.
std::vector<std::pair<std::string_view, std::string_view>> viewerScripts();
std::string_view threeJs();
std::string_view orbitControlsJs();

}  // namespace simbot::reports
