// Linked instead of the generated page_assets.cpp when the page could not be built (no node or no
// viewer/web/node_modules at configure time): no page, the server says so at GET /.
#include "viewer/page_assets.h"

namespace plumb::viewer {

std::vector<HttpAsset> pageAssets() { return {}; }

}  // namespace plumb::viewer
