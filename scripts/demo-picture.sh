#!/usr/bin/env bash
# The README demo's penetrating pose (pose 2: the gripper's fingers 2 cm into the table) as a
# picture: the per-point output of `pcd_collision -o`, without and with -surface, seen from the
# side. Writes docs/images/demo_pose2.png (gnuplot). Run after the build:
#   scripts/demo-picture.sh [--out=FILE] [--tool=PATH]   (PATH: build/tools/pcd_collision unset)
# Prints both answers; ctest's demo_picture_script checks them and the PNG.
set -euo pipefail
usage="usage: scripts/demo-picture.sh [--out=FILE] [--tool=PATH]"
# A relative --out or --tool is the caller's: made absolute before the script moves to the root.
absolute() { case "$1" in /*) echo "$1" ;; *) echo "$PWD/$1" ;; esac; }
out=""
tool=""
for a in "$@"; do
  case "$a" in
    --out=?*) out=$(absolute "${a#--out=}") ;;
    --tool=?*) tool=$(absolute "${a#--tool=}") ;;
    -h|--help) echo "$usage"; exit 0 ;;
    *) echo "$usage" >&2; exit 2 ;;
  esac
done
cd "$(dirname "$0")/.."
out=${out:-docs/images/demo_pose2.png}
tool=${tool:-build/tools/pcd_collision}
[ -x "$tool" ] || { echo "demo-picture.sh: $tool: no such executable (build it: cmake --build build)" >&2; exit 2; }
command -v gnuplot > /dev/null || { echo "demo-picture.sh: gnuplot not found (scripts/install-deps.sh)" >&2; exit 2; }

# Pose 2 of data/demo_poses.txt, its third pose line.
pose=$(grep -v '^#' data/demo_poses.txt | awk 'NF >= 6 { if (++n == 3) { print $1 "," $2 "," $3 "," $4 "," $5 "," $6; exit } }')
[ -n "$pose" ] || { echo "demo-picture.sh: no third pose in data/demo_poses.txt" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# One run per panel: its result line becomes the panel's title, its -o file the points.
run() {
  local name=$1; shift
  "$tool" data/gripper.obj data/table_mug.pcd -pose="$pose" -o "$tmp/$name.pcd" "$@" > "$tmp/$name.log" 2>&1 ||
    { cat "$tmp/$name.log" >&2; exit 1; }
  awk '$1 == "free" || $1 == "contact" || $1 == "collision" { print $1, $2, $3, $4; exit }' "$tmp/$name.log" > "$tmp/$name.title"
  # gnuplot reads the binary PCD in place: the header's length and the point count.
  local header points
  header=$(grep -abo 'DATA binary' "$tmp/$name.pcd" | head -1 | cut -d: -f1)
  points=$(grep -a '^POINTS ' "$tmp/$name.pcd" | head -1 | awk '{ print $2 }')
  grep -aq '^FIELDS x y z intensity rgb label$' "$tmp/$name.pcd" && grep -aq '^SIZE 4 4 4 4 4 4$' "$tmp/$name.pcd" &&
    [ -n "$header" ] && [ -n "$points" ] ||
    { echo "demo-picture.sh: $tmp/$name.pcd: not the binary layout this script reads (x y z intensity rgb label, 4 bytes each)" >&2; exit 1; }
  echo "$((header + 12)) $points" > "$tmp/$name.layout"
}
run separators
run surface -surface

mkdir -p "$(dirname "$out")"
gnuplot -e "dir='$tmp'; out='$out.tmp'" scripts/demo-picture.gp
# a PNG, not an error page: its signature
[ "$(head -c 8 "$out.tmp" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] ||
  { echo "demo-picture.sh: gnuplot wrote no PNG" >&2; exit 1; }
mv "$out.tmp" "$out"
echo "demo-picture.sh: wrote $out (default: $(cat "$tmp/separators.title"); -surface: $(cat "$tmp/surface.title"))"
