#!/usr/bin/env bash
# Runs a command that needs an X display (OpenGL rendering).
# With DISPLAY set, the command runs as it is. Without one (CI, ssh, containers)
# it gets a private Xvfb with Mesa's llvmpipe (OpenGL 4.5 core) on a random display
# number (retried if taken), reported through -displayfd once the server accepts
# connections, with -noreset: by default the server resets when its last client
# disconnects, and a program that closes its only render window and opens another
# (TestCloudSky, pvpython) could then meet a server in mid-reset: "bad X server
# connection", seen once in several runs. Not the lowest free number: a server shutting down removes its socket
# late, and a new server reusing that number at that moment would lose its own.
# With neither a DISPLAY nor Xvfb, the command runs with NIMBUS_OFFSCREEN=egl exported:
# Nimbus's programs, Python scripts and plugin then render on an EGL pbuffer, no X at all.
set -u
if [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
if ! command -v Xvfb >/dev/null 2>&1; then
  if [ -z "${NIMBUS_OFFSCREEN:-}" ] || [ "${NIMBUS_OFFSCREEN}" = 0 ]; then
    echo "with-display.sh: no DISPLAY and no Xvfb: rendering without X (NIMBUS_OFFSCREEN=egl)" >&2
    export NIMBUS_OFFSCREEN=egl
  fi
  exec "$@"
fi

scratch="$(mktemp -d)"
xvfb_pid=""
cleanup() {
  if [ -n "$xvfb_pid" ]; then
    kill "$xvfb_pid" 2>/dev/null
    wait "$xvfb_pid" 2>/dev/null
  fi
  rm -rf "$scratch"
}
trap cleanup EXIT

started=""
for attempt in 1 2 3 4 5 6 7 8; do
  number=$((1000 + RANDOM % 30000))
  [ -e "/tmp/.X${number}-lock" ] && continue
  : >"$scratch/display"
  Xvfb ":$number" -displayfd 3 -screen 0 1280x1024x24 -nolisten tcp -noreset \
    3>"$scratch/display" 2>"$scratch/xvfb.log" &
  xvfb_pid=$!
  for _ in $(seq 200); do # up to 20 s
    [ -s "$scratch/display" ] && break
    kill -0 "$xvfb_pid" 2>/dev/null || break
    sleep 0.1
  done
  if [ -s "$scratch/display" ]; then
    started=yes
    break
  fi
  kill "$xvfb_pid" 2>/dev/null
  wait "$xvfb_pid" 2>/dev/null
  xvfb_pid=""
done
if [ -z "$started" ]; then
  echo "with-display.sh: Xvfb failed to start:" >&2
  cat "$scratch/xvfb.log" >&2
  exit 1
fi
DISPLAY=":$(head -n 1 "$scratch/display")"
export DISPLAY
"$@"
status=$?
if [ "$status" -ne 0 ] && [ -s "$scratch/xvfb.log" ]; then
  echo "with-display.sh: the command failed ($status) on $DISPLAY; Xvfb said:" >&2
  cat "$scratch/xvfb.log" >&2
fi
exit "$status"
