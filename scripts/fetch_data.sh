#!/usr/bin/env bash
# Fetches the real data of ../shared/DATA.md from Debian's archive into a cache outside git:
#   ${UWSCAN_DATA_CACHE:-$HOME/.cache/uwscan}/meshes/*.off   CGAL's scanned and CAD meshes
#   ${UWSCAN_DATA_CACHE:-$HOME/.cache/uwscan}/scans/*.pcd    PCL's tutorial scans and models
# Idempotent: does nothing once the cache holds every file. Prints the cache folder.
set -euo pipefail
cache=${UWSCAN_DATA_CACHE:-$HOME/.cache/uwscan}
meshes=(anchor cylinder joint rotor spool turbine pinion_small fandisk_large bunny00
        dragknob part handle mech-holes-shark ALSTOM_TEST4 itemb)
scans=(bun0 table_scene_lms400 milk milk_cartoon_all_small_clorox)

complete() {
  for m in "${meshes[@]}"; do [ -s "$cache/meshes/$m.off" ] || return 1; done
  for s in "${scans[@]}"; do [ -s "$cache/scans/$s.pcd" ] || return 1; done
}

if ! complete; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  mkdir -p "$cache/meshes" "$cache/scans"
  download() { (cd "$work" && apt-get download -qq libcgal-demo python3-pcl >/dev/null 2>&1); }
  # A machine whose package lists were never fetched cannot download: refresh them (as root).
  if ! download && ! { [ "$(id -u)" -eq 0 ] && apt-get update -qq >/dev/null 2>&1 && download; }; then
    echo "fetch_data: apt-get download libcgal-demo python3-pcl failed (run apt-get update?)" >&2
    exit 1
  fi
  dpkg-deb -x "$work"/libcgal-demo_*.deb "$work/cgal"
  tar xzf "$work/cgal/usr/share/doc/libcgal-dev/data.tar.gz" -C "$work/cgal"
  for m in "${meshes[@]}"; do
    cp "$work/cgal/data/meshes/$m.off" "$cache/meshes/$m.off.tmp" && mv "$cache/meshes/$m.off.tmp" "$cache/meshes/$m.off"
  done
  dpkg-deb -x "$work"/python3-pcl_*.deb "$work/pcl"
  examples="$work/pcl/usr/share/doc/python3-pcl/examples"
  cp "$examples/official/Surface/bun0.pcd" "$cache/scans/bun0.pcd"
  cp "$examples/pcldata/tutorials/table_scene_lms400.pcd" "$cache/scans/table_scene_lms400.pcd"
  for s in milk milk_cartoon_all_small_clorox; do
    cp "$examples/pcldata/tutorials/correspondence_grouping/$s.pcd" "$cache/scans/$s.pcd"
  done
fi
echo "$cache"
