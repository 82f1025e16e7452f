#pragma once

#include <filesystem>

namespace uwscan::app {

// Folder of the real data fetched by scripts/fetch_data.sh: $UWSCAN_DATA_CACHE, else
// ~/.cache/uwscan. Throws uwscan::Error telling how to fetch it when it is missing.
std::filesystem::path DataCache();

// Folder where per-calibration tables are kept between runs: $UWSCAN_TABLE_CACHE, else
// $XDG_CACHE_HOME/uwscan/tables, else ~/.cache/uwscan/tables; empty when none can be named.
std::filesystem::path TableCache();

}  // namespace uwscan::app
