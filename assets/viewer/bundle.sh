#!/usr/bin/env bash
# Makes three.min.js, the part of three.js that the `.html` viewer page inlines, from the
# pinned npm packages: three.js's WebGL renderer, GLTFLoader and OrbitControls (three-entry.mjs)
# as one minified script that sets the global HALO4D_THREE. Run it after changing the pins or
# the entry, and commit the result (the build includes it; it needs no network).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
three=three@0.187.0
esbuild=esbuild@0.28.2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
npm install --prefix "$work" --no-save --no-package-lock --no-audit --no-fund "$three" "$esbuild" >/dev/null
cp "$here/three-entry.mjs" "$work/"
{
  echo "/* three.js ${three#three@}: WebGLRenderer, GLTFLoader and OrbitControls for halo4d's viewer"
  echo "   page, made by assets/viewer/bundle.sh. Its licence:"
  echo
  sed 's/^/   /' "$work/node_modules/three/LICENSE"
  echo "*/"
  (cd "$work" && ./node_modules/.bin/esbuild three-entry.mjs --bundle --minify --format=iife \
    --global-name=HALO4D_THREE --legal-comments=none --target=es2020)
} > "$here/three.min.js"
echo "wrote $here/three.min.js ($(wc -c < "$here/three.min.js") bytes)"
