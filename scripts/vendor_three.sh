#!/usr/bin/env bash
# three.js for the web player (motionlab.viz.web), from npm, bundled into ONE classic script that
# defines window.THREE: build/web/three.min.js. A classic script (not an ES module) is what a page
# opened from file:// may load. scripts/build_docs.sh copies it into the site; in JupyterLab and
# VS Code, motionlab.viz.web.player embeds it by itself (three_js="auto", the default there: in the
# first player of a kernel; MOTIONLAB_WEB_EMBED=0 turns that off). Needs node + npm and the npm registry
# (once: the file is kept and reused while the versions below stay the same).
set -euo pipefail
cd "$(dirname "$0")/.."
THREE_VERSION=0.187.0
ESBUILD_VERSION=0.28.2
OUT=build/web/three.min.js
WORK=build/web-npm
if [ -f "$OUT" ] && head -c 200 "$OUT" | grep -q "three@$THREE_VERSION "; then
  exit 0
fi
mkdir -p "$WORK" "$(dirname "$OUT")"
npm install --silent --no-audit --no-fund --prefix "$WORK" "three@$THREE_VERSION" "esbuild@$ESBUILD_VERSION" >/dev/null
# only what web_player.js uses, so the bundle stays small
cat > "$WORK/entry.js" <<'JS'
export {
  WebGLRenderer, Scene, Color, HemisphereLight, DirectionalLight, GridHelper, PerspectiveCamera,
  CylinderGeometry, SphereGeometry, MeshLambertMaterial, InstancedMesh, Matrix4, Quaternion, Vector3,
} from "three";
JS
"$WORK/node_modules/.bin/esbuild" "$WORK/entry.js" --bundle --format=iife --global-name=THREE --minify \
  --log-level=warning --banner:js="/* three@$THREE_VERSION (MIT, https://threejs.org), bundled for motionlab's web player */" \
  --outfile="$OUT.tmp"
mv "$OUT.tmp" "$OUT"
echo "three.js $THREE_VERSION: $OUT ($(du -k "$OUT" | cut -f1) kB)"
