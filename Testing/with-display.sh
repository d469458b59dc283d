#!/usr/bin/env bash
# Runs a command that needs an X display (OpenGL rendering).
# With DISPLAY set, the command runs as it is. Without one (CI, ssh, containers)
# it gets a private Xvfb with Mesa's llvmpipe (OpenGL 4.5 core): Xvfb picks a
# free display number itself (-displayfd) and reports it once it accepts
# connections, so parallel tests cannot race for a number.
set -u
if [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
if ! command -v Xvfb >/dev/null 2>&1; then
  echo "with-display.sh: no DISPLAY and no Xvfb; install the 'xvfb' package" >&2
  exit 1
fi

scratch="$(mktemp -d)"
Xvfb -displayfd 3 -screen 0 1280x1024x24 -nolisten tcp 3>"$scratch/display" 2>"$scratch/xvfb.log" &
xvfb_pid=$!
cleanup() {
  kill "$xvfb_pid" 2>/dev/null
  wait "$xvfb_pid" 2>/dev/null
  rm -rf "$scratch"
}
trap cleanup EXIT

for _ in $(seq 200); do # up to 20 s
  [ -s "$scratch/display" ] && break
  if ! kill -0 "$xvfb_pid" 2>/dev/null; then
    echo "with-display.sh: Xvfb failed to start:" >&2
    cat "$scratch/xvfb.log" >&2
    exit 1
  fi
  sleep 0.1
done
if [ ! -s "$scratch/display" ]; then
  echo "with-display.sh: Xvfb did not report a display within 20 s" >&2
  exit 1
fi
DISPLAY=":$(head -n 1 "$scratch/display")"
export DISPLAY
"$@"
