#!/usr/bin/env bash
# Regenerates the figure sheets in docs/figures/ like the paper's Figures 1–3, and the charts:
#   bash docs/figures/make.sh
# Builds the release binary, renders each scene into a temporary directory with
# `wraptree snapshot` and keeps only the sheet (figure.png). Deterministic: same bytes each run.
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --quiet
bin=target/release/wraptree
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

snap() { # NAME SCENE ARGS...
  local name=$1 scene=$2
  shift 2
  "$bin" snapshot "scenes/$scene" -o "$tmp/$name" "$@" >/dev/null
  cp "$tmp/$name/figure.png" "docs/figures/$name.png"
  echo "docs/figures/$name.png ($(stat -c %s "docs/figures/$name.png") bytes)"
}

# Figure 1: the robot base at the levels nearest 251, 104 and 8 nodes.
snap robot-base robot-base.obj --nodes 251,104,8 --size 480x360
# Figure 2: the lamp, the levels nearest 167 and 4 nodes as spheres, then as convex hulls.
snap lamp lamp.obj --nodes 167,4 --wrapper sphere,hull --size 400x320
# Figure 3: five lamps, the 8-node level as spheres and as convex hulls.
snap lamps5 lamps5.obj --nodes 8 --wrapper sphere,hull --size 480x400

# Charts (timings vary from run to run, so these bytes do too): the stability study's
# spaghetti chart, and the speed-against-accuracy charts of the 12,144-polygon scene.
mkdir -p "$tmp/stress" "$tmp/bench"
"$bin" stress -o "$tmp/stress" >/dev/null
cp "$tmp/stress/spaghetti.png" docs/figures/spaghetti.png
"$bin" bench robot-bases -o "$tmp/bench" >/dev/null
cp "$tmp/bench/robot-bases-time_vs_query.png" docs/figures/robot-bases-time_vs_query.png
cp "$tmp/bench/robot-bases-wrapper_time_vs_tightness.png" docs/figures/robot-bases-wrapper_time_vs_tightness.png
echo "docs/figures/{spaghetti,robot-bases-time_vs_query,robot-bases-wrapper_time_vs_tightness}.png"
