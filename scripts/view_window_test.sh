#!/usr/bin/env bash
# The window tested as a user drives it: `fiblet view` on a virtual X
# display (Xvfb), keys and clicks sent with xdotool, and the window's own
# screenshots (S: the scene alone, never the panel) compared:
#   T cycles lines -> tubes -> capsules -> lines (lines again: the same image);
#   the panel's "tubes" button draws what T draws;
#   the wheel zooms, a drag orbits, R resets (the first image again);
#   a click on a fiber prints it and highlights it (the others dimmed);
#   P hides the panel (a click where a button was reaches the scene);
#   Q quits with status 0;
#   under --gpu-memory below the file's scene, the overview is drawn first,
#   then a part of the fibers of the resting view, again after a zoom.
#   scripts/view_window_test.sh FIBLET INPUT [STREAMED_INPUT]
# (STREAMED_INPUT, default INPUT: the --gpu-memory case; a file of a few
# hundred blocks or more, so that a part of it is more than the frames
# every scene holds.)
# Needs Xvfb and xdotool (scripts/setup.sh); exit 1 on the first failure.
set -euo pipefail
FIBLET=$(realpath "$1")
INPUT=$(realpath "$2")
STREAMED=$(realpath "${3:-$2}")
for tool in Xvfb xdotool python3; do
  command -v "$tool" >/dev/null || { echo "view_window_test: needs $tool (scripts/setup.sh)" >&2; exit 1; }
done

WORK=$(mktemp -d)
VIEWER=""
XVFB=""
cleanup() {
  [ -n "$VIEWER" ] && kill "$VIEWER" 2>/dev/null || true
  [ -n "$XVFB" ] && kill "$XVFB" 2>/dev/null || true
  rm -rf "$WORK"
}
trap cleanup EXIT
fail() { echo "view_window_test: FAIL: $*" >&2; echo "--- fiblet view's output:" >&2; cat "$WORK/view.log" >&2; exit 1; }

# A free display: Xvfb writes the number it took (-displayfd).
Xvfb -displayfd 3 -screen 0 800x600x24 -nolisten tcp 3>"$WORK/display" 2>"$WORK/xvfb.log" &
XVFB=$!
for _ in $(seq 100); do [ -s "$WORK/display" ] && break; sleep 0.1; done
[ -s "$WORK/display" ] || fail "Xvfb did not start: $(cat "$WORK/xvfb.log")"
export DISPLAY=":$(cat "$WORK/display")"

cd "$WORK"
export FIBLET_VIEW_PANEL_LAYOUT="$WORK/layout.txt"
"$FIBLET" view "$INPUT" --size 640x480 >"$WORK/view.log" 2>&1 &
VIEWER=$!
WINDOW=$(timeout 60 xdotool search --sync --onlyvisible --name "$(basename "$INPUT")" | head -1) ||
  fail "no window within 60 s"
for _ in $(seq 300); do grep -q "^style/tubes" layout.txt 2>/dev/null && break; sleep 0.1; done
grep -q "^style/tubes" layout.txt 2>/dev/null || fail "the panel wrote no layout"

# Sends the keys, then S, and waits for the screenshot it writes.
shot() {
  for key in "$@"; do xdotool key --window "$WINDOW" "$key"; sleep 0.3; done
  local name taken
  taken=$(find . -maxdepth 1 -name 'fiblet-screenshot-*.png' | wc -l)
  name=$(printf "fiblet-screenshot-%03d.png" $((taken + 1)))
  xdotool key --window "$WINDOW" s
  for _ in $(seq 300); do [ -s "$name" ] && break; sleep 0.1; done
  [ -s "$name" ] || fail "no screenshot $name"
  sleep 0.3  # the PNG is written whole before the message; give the file a moment
  echo "$name"
}
# The centre of a panel control, in window pixels.
centre() {
  awk -F'\t' -v label="$1" '$1 == label { split($2, r, " "); printf "%d %d\n", (r[1] + r[3]) / 2, (r[2] + r[4]) / 2 }' layout.txt
}
click() {  # click X Y
  xdotool mousemove --window "$WINDOW" "$1" "$2"
  sleep 0.3
  xdotool click --window "$WINDOW" 1
  sleep 0.5
}
click_control() {  # click LABEL: the panel control's centre
  local x y
  read -r x y < <(centre "$1")
  click "$x" "$y"
}
quit_viewer() {  # Q quits, with status 0
  xdotool key --window "$WINDOW" q
  for _ in $(seq 100); do kill -0 "$VIEWER" 2>/dev/null || break; sleep 0.1; done
  wait "$VIEWER" || fail "fiblet view $1 exited with status $?"
  VIEWER=""
}
same() { cmp -s "$1" "$2" || fail "$3: $1 and $2 differ"; }
differ() { cmp -s "$1" "$2" && fail "$3: $1 and $2 are the same" || true; }

lines=$(shot)
tubes=$(shot t)
differ "$lines" "$tubes" "T: tubes"
capsules=$(shot t)
differ "$tubes" "$capsules" "T: capsules"
again=$(shot t)
same "$lines" "$again" "T back to lines"

click_control "style/tubes"
panel_tubes=$(shot)
same "$tubes" "$panel_tubes" "the panel's tubes button"
click_control "style/lines"

# The pointer rests over the scene first: the panel decides whether it
# takes the wheel from where the pointer was at the last frame (after the
# click above, over the panel), so a move and a wheel in one frame, as a
# loaded machine delivers them, would go to the panel.
xdotool mousemove --window "$WINDOW" 480 240
sleep 0.5
xdotool click --window "$WINDOW" 4
sleep 0.5
zoomed=$(shot)
differ "$lines" "$zoomed" "the wheel's zoom"
reset=$(shot r)
same "$lines" "$reset" "R: reset"
# A left drag orbits (no pick: the pointer moved), R resets again.
xdotool mousemove --window "$WINDOW" 480 240
sleep 0.5
xdotool mousedown --window "$WINDOW" 1
for x in 490 500 520 540; do xdotool mousemove --window "$WINDOW" "$x" 250; sleep 0.1; done
xdotool mouseup --window "$WINDOW" 1
sleep 0.5
orbited=$(shot)
differ "$lines" "$orbited" "a drag's orbit"
grep -q "^fiber ID\|^no fiber" view.log && fail "a drag picked"
same "$lines" "$(shot r)" "R after the orbit"

# A fiber's pixel, right of the panel: the brightest of the lines image.
read -r fx fy < <(python3 - "$lines" "$(centre "style/capsules" | cut -d' ' -f1)" <<'EOF'
import sys, zlib, struct
data = open(sys.argv[1], "rb").read()
pos, chunks = 8, []
width = height = 0
while pos < len(data):
    n, kind = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    if kind == b"IHDR":
        width, height, depth, color = struct.unpack(">IIBB", body[:10])
        assert depth == 8 and color in (2, 6), "8-bit RGB(A) PNG expected"
        channels = 3 if color == 2 else 4
    elif kind == b"IDAT":
        chunks.append(body)
    pos += 12 + n
raw, stride, rows, prev = zlib.decompress(b"".join(chunks)), width * channels, [], bytearray(width * channels)
for r in range(height):
    f, line = raw[r * (stride + 1)], bytearray(raw[r * (stride + 1) + 1:(r + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - channels] if i >= channels else 0
        b, c = prev[i], prev[i - channels] if i >= channels else 0
        if f == 1: line[i] = (line[i] + a) & 255
        elif f == 2: line[i] = (line[i] + b) & 255
        elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
        elif f == 4:
            p = a + b - c
            pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
    rows.append(line)
    prev = line
x_min = int(sys.argv[2]) + 80  # clear of the panel
best = max((sum(rows[y][x * channels:x * channels + 3]), x, y)
           for y in range(height) for x in range(x_min, width))
print(best[1], best[2])
EOF
)
click "$fx" "$fy"
grep -q "^fiber ID" view.log || fail "a click on a fiber at ($fx, $fy) printed no fiber"
picked=$(shot)
differ "$lines" "$picked" "the picked fiber's highlight"
click_control "clear"
cleared=$(shot)
same "$lines" "$cleared" "the panel's clear button"

# P hides the panel: its tubes button's place is the scene's again (a click
# there picks or clears, and never changes the style).
read -r x y < <(centre "style/tubes")
xdotool key --window "$WINDOW" p
sleep 0.3
click "$x" "$y"
hidden=$(shot)
differ "$tubes" "$hidden" "P: the hidden panel's button still drew tubes"

quit_viewer ""

# Beyond --gpu-memory (60 % of what the file's scene takes): the overview
# first, then the fibers of the resting view, and again after a zoom.
whole_bytes=$("$FIBLET" render "$STREAMED" -o "$WORK/whole.png" --size 64x48 --json |
  python3 -c 'import json, sys; print(json.load(sys.stdin)["scene"]["gpu_bytes"])')
budget=$(python3 -c "print(0.6 * $whole_bytes / 1048576)")
rm -f fiblet-screenshot-*.png
"$FIBLET" view "$STREAMED" --size 640x480 --gpu-memory "$budget" >"$WORK/view.log" 2>&1 &
VIEWER=$!
WINDOW=$(timeout 60 xdotool search --sync --onlyvisible --name "$(basename "$STREAMED")" | head -1) ||
  fail "no window within 60 s (--gpu-memory $budget)"
views_drawn() { grep -c "^the view's fibers' frame drawn" view.log || true; }
wait_views() {  # wait_views N: until the N-th view's fibers are drawn
  for _ in $(seq 300); do [ "$(views_drawn)" -ge "$1" ] && return; sleep 0.1; done
  fail "the view's fibers were not drawn a ${1}th time"
}
# The viewer prints its streaming line before it opens the window, but the
# log is a file (block-buffered): wait for it rather than race the flush.
for _ in $(seq 300); do grep -q "^beyond --gpu-memory" view.log && break; sleep 0.1; done
grep -q "^beyond --gpu-memory" view.log || fail "--gpu-memory $budget MiB: the file was not streamed"
wait_views 1
grep -q "^first frame drawn" view.log || fail "no first frame (the overview)"
held=$(sed -n "s/^the view's fibers' frame drawn .* (\([0-9]*\) of \([0-9]*\) fibers.*/\1 \2/p" view.log | head -1)
read -r n_held n_file <<<"$held"
[ "$n_held" -gt 0 ] && [ "$n_held" -lt "$n_file" ] || fail "held $n_held of $n_file fibers"
first_view=$(shot)
xdotool mousemove --window "$WINDOW" 480 240 click --window "$WINDOW" 4 click --window "$WINDOW" 4
wait_views 2
zoomed_view=$(shot)
differ "$first_view" "$zoomed_view" "the zoomed view's fibers"
quit_viewer "--gpu-memory"
echo "view_window_test: ok ($(find . -maxdepth 1 -name 'fiblet-screenshot-*.png' | wc -l) screenshots compared)"
