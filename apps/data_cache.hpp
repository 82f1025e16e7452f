#pragma once

#include <filesystem>

namespace uwscan::app {

// Folder of the real data fetched by scripts/fetch_data.sh: $UWSCAN_DATA_CACHE, else
// ~/.cache/uwscan. Throws uwscan::Error telling how to fetch it when it is missing.
std::filesystem::path DataCache();

}  // namespace uwscan::app
