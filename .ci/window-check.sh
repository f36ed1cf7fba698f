#!/usr/bin/env bash
# The viewer's window on a virtual X display: it opens, shows its settings in the title,
# answers the keys, a drag and the wheel, and quits on Q. Usage: .ci/window-check.sh SCENE.glb
set -euo pipefail
glb=$1
if ! command -v Xvfb >/dev/null || ! command -v xdotool >/dev/null; then
  apt-get update -qq && apt-get install -y -qq xvfb xdotool
fi
Xvfb :97 -screen 0 1280x1024x24 >/dev/null 2>&1 &
xvfb=$!
trap 'kill "$xvfb" 2>/dev/null || true' EXIT
export DISPLAY=:97
sleep 1
./target/release/halo4d-view "$glb" --size 480x360 --slices 64 --azimuth 35 &
viewer=$!
w=
for _ in $(seq 1 150); do
  w=$(xdotool search --name '^halo4d-view' 2>/dev/null | head -n 1 || true)
  [ -n "$w" ] && break
  sleep 0.2
done
[ -n "$w" ] || { echo "no viewer window appeared"; exit 1; }
# No window manager: give the window the keyboard, then type (XTEST) and drag.
xdotool windowfocus "$w" 2>/dev/null || true
# Waits until the window's title contains $1.
expect() {
  local t=
  for _ in $(seq 1 150); do
    t=$(xdotool getwindowname "$w" 2>/dev/null || true)
    case "$t" in *"$1"*) echo "  $t"; return 0 ;; esac
    sleep 0.2
  done
  echo "the window's title never showed '$1' (last: '$t')"
  exit 1
}
expect "grid 64 slices | 1 spp | halos on | curves on | silhouettes on | opaque | colour by w | azimuth 35"
xdotool key s; expect "grid 128 slices"
xdotool key m; expect "view 128 slices"
xdotool key h; expect "halos off"
xdotool key c; expect "curves off"
xdotool key o; expect "silhouettes off"
xdotool key t; expect "transparent"
xdotool key w; expect "colour grey"
xdotool mousemove --window "$w" 200 150 mousedown 1 mousemove --window "$w" 300 150 mouseup 1
expect "azimuth 355"
xdotool mousemove --window "$w" 240 180 click 4; expect "distance 2."
xdotool key r; expect "azimuth 35 elevation 25 distance 3.20"
xdotool key q
wait "$viewer"
echo "the viewer's window answered every key and quit"
