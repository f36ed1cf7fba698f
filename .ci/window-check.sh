#!/usr/bin/env bash
# The viewer's window on a virtual X display: it opens, shows its settings in the title,
# answers the keys, a drag and the wheel, and quits on Q; on a scene file it turns in 4D (a
# plane key, a Shift drag), settles its curves, searches a view, resets, shows and moves the
# slice by a hyperplane, and saves the view.
# Usage: .ci/window-check.sh SCENE.glb SCENE.json (a scene whose view turns only yw by 30)
set -euo pipefail
glb=$1
scene=$2
if ! command -v Xvfb >/dev/null || ! command -v xdotool >/dev/null; then
  apt-get update -qq && apt-get install -y -qq xvfb xdotool
fi
# A key held 1.5 s repeats twice (after 300 ms, then every second), so the check below can tell
# one step from a step per repeat whatever the machine's load.
# Xvfb picks a free display and writes its number once it accepts connections (-displayfd), so
# a busy machine or a display left over by another run cannot make the viewer start too early.
displayfile=$(mktemp)
Xvfb -displayfd 3 -screen 0 1280x1024x24 -ardelay 300 -arinterval 1000 3>"$displayfile" >/dev/null 2>&1 &
xvfb=$!
trap 'kill "$xvfb" 2>/dev/null || true; rm -f "$displayfile"' EXIT
for _ in $(seq 1 300); do
  [ -s "$displayfile" ] && break
  kill -0 "$xvfb" 2>/dev/null || { echo "Xvfb exited before it opened a display"; exit 1; }
  sleep 0.1
done
[ -s "$displayfile" ] || { echo "Xvfb opened no display in 30 s"; exit 1; }
export DISPLAY=":$(head -n 1 "$displayfile")"
# Waits for a window of the viewer ($1: its pid) and gives it the keyboard.
w=
find_window() {
  w=
  for _ in $(seq 1 150); do
    w=$(xdotool search --pid "$1" --name '^halo4d-view' 2>/dev/null | head -n 1 || true)
    [ -n "$w" ] && break
    sleep 0.2
  done
  [ -n "$w" ] || { echo "no viewer window appeared"; exit 1; }
  # No window manager: give the window the keyboard, then type (XTEST) and drag.
  xdotool windowfocus "$w" 2>/dev/null || true
}
# Waits until the window's title contains $1.
expect() {
  local t=
  for _ in $(seq 1 300); do
    t=$(xdotool getwindowname "$w" 2>/dev/null || true)
    case "$t" in *"$1"*) echo "  $t"; return 0 ;; esac
    sleep 0.2
  done
  echo "the window's title never showed '$1' (last: '$t')"
  exit 1
}
# Waits until the window's title no longer contains $1.
expect_not() {
  local t=
  for _ in $(seq 1 300); do
    t=$(xdotool getwindowname "$w" 2>/dev/null || true)
    case "$t" in *"$1"*) ;; *) echo "  $t"; return 0 ;; esac
    sleep 0.2
  done
  echo "the window's title kept showing '$1' (last: '$t')"
  exit 1
}
./target/release/halo4d-view "$glb" --size 480x360 --slices 64 --azimuth 35 &
viewer=$!
find_window "$viewer"
expect "grid 64 slices | 1 spp | halos on | curves on | silhouettes on | opaque | colour by w | azimuth 35"
# S held down takes one step (64 to 128 slices), not one per auto-repeat (256 or 512).
xdotool keydown s; sleep 1.5; xdotool keyup s; expect "grid 128 slices"
sleep 0.5; expect "grid 128 slices"
xdotool key m; expect "view 128 slices"
xdotool key h; expect "halos off"
xdotool key c; expect "curves off"
xdotool key o; expect "silhouettes off"
xdotool key t; expect "transparent"
xdotool key w; expect "colour grey"
# D draws stipples (made once in the background from the file's 4D mesh), and back.
xdotool key d; expect "| stipples |"
xdotool key d; expect "| shaded |"
xdotool mousemove --window "$w" 200 150 mousedown 1 mousemove --window "$w" 300 150 mouseup 1
expect "azimuth 355"
# The camera is fitted (the file's scene records no distance); the wheel zooms from there
# (the title drops "fitted"), and R goes back to the fit.
xdotool mousemove --window "$w" 240 180 click 4; expect_not " fitted | "
xdotool key r; expect "azimuth 35 elevation -42 distance"; expect " fitted | "
xdotool key q
wait "$viewer"
echo "the viewer's window answered every key and quit"

./target/release/halo4d-view "$scene" --size 480x360 --slices 64 &
viewer=$!
find_window "$viewer"
expect "4D xy 0 xz 0 xw 0 yz 0 yw 30 zw 0 orthographic"
expect "settled"
xdotool key 3; expect "4D xy 0 xz 0 xw 15 yz 0 yw 30 zw 0 orthographic"
xdotool key shift+3; expect "4D xy 0 xz 0 xw 0 yz 0 yw 30 zw 0 orthographic"
# The 4D rolling ball: Shift and a drag across the window turn the drag's direction towards w.
xdotool mousemove --window "$w" 150 180 keydown shift mousedown 1 mousemove --window "$w" 250 180 mouseup 1 keyup shift
t=$(xdotool getwindowname "$w")
for _ in $(seq 1 100); do
  case "$t" in *"4D xy 0 xz 0 xw 0 yz 0 yw 30 zw 0 orthographic"*) sleep 0.2; t=$(xdotool getwindowname "$w") ;; *) break ;; esac
done
case "$t" in
  *"4D xy 0 xz 0 xw 0 yz 0 yw 30 zw 0 orthographic"*) echo "a Shift drag did not turn the 4D view: $t"; exit 1 ;;
esac
echo "  $t"
expect "settled"
# While a drag turns the scene in 4D its frames are sliced at 64, at the settings' own once
# it stops.
xdotool key s; expect "grid 128 slices"
xdotool mousemove --window "$w" 150 180 keydown shift mousedown 1 mousemove --window "$w" 200 180 sleep 0.5 mousemove --window "$w" 250 180
expect "grid 64 slices while turning (128 when still)"
xdotool mouseup 1 keyup shift; expect "grid 128 slices | "
expect "settled"
# The view search runs in the background and turns the view to what it found.
xdotool key a; expect "searching the view"
expect "view search:"
xdotool key v; expect "4D xy 0 xz 0 xw 0 yz 0 yw 30 zw 0 orthographic"
# A held turn key repeats its step: 3 held 1.5 s turns xw by 15 degrees, then 15 more per repeat.
xdotool keydown 3; sleep 1.5; xdotool keyup 3; expect_not "4D xy 0 xz 0 xw 0 "; expect_not " xw 15 "
xdotool key v; expect "4D xy 0 xz 0 xw 0 yz 0 yw 30 zw 0 orthographic"
# The moving hyperplane: L shows its slice (the title names its level and curves), the
# period key moves it up, L hides it and shows it again at the level it had.
xdotool key l; expect "| slice h = "
level=$(xdotool getwindowname "$w" | grep -o 'slice h = [-0-9.]*')
xdotool key period; expect_not "$level"; expect "| slice h = "
moved=$(xdotool getwindowname "$w" | grep -o 'slice h = [-0-9.]*:')
xdotool key l; expect_not "slice h = "
xdotool key l; expect "$moved"
xdotool key l; expect_not "slice h = "
xdotool key f; expect "saved exports/views/"
xdotool key q
wait "$viewer"
echo "the explorer turned the scene in 4D, settled its curves, moved its hyperplane and saved the view"
