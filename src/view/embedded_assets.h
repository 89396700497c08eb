// The files a review page is made of, embedded into the library when it is built
// (embedded_assets.cpp.in): the page's HTML skeleton, style sheet and script, the batch index
// page, and three.js r111 with its OrbitControls (Debian's libjs-three, MIT licence).
#pragma once

#include <string_view>

namespace dispex::view {

enum class Asset { kPageHtml, kViewerCss, kViewerJs, kIndexHtml, kThreeJs, kOrbitControlsJs };

// The file's bytes (valid for the program's life).
std::string_view EmbeddedAsset(Asset asset);

}  // namespace dispex::view
