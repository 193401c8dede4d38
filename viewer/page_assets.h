#pragma once
// plumb's own viewer page (viewer/web/, docs/VIEWER.md): index.html and the bundle esbuild made of
// viewer/web/src with three.js from npm (viewer/web/package-lock.json), embedded in the binary at
// build time (viewer/CMakeLists.txt). Empty when the build had no node/npm packages: the server
// then answers GET / with a note and Foxglove/Lichtblick still work.
#include <vector>

#include "viewer/foxglove_server.h"

namespace plumb::viewer {

std::vector<HttpAsset> pageAssets();

}  // namespace plumb::viewer
