// The viewer's files, compiled into simbot (tools/viewer_assets.cpp): the
// page template, its script and style, and three.js with its orbit
// controls from Debian's libjs-three.
#pragma once
#include <string_view>

namespace simbot::tools::assets {

std::string_view viewerHtml();
std::string_view viewerCss();
std::string_view viewerJs();
std::string_view threeJs();
std::string_view orbitControlsJs();

}  // namespace simbot::tools::assets
