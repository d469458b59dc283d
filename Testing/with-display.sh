#!/bin/sh
# Runs a command that needs an X display (OpenGL rendering).
# With DISPLAY set, the command runs as it is; without one (CI, ssh, containers)
# it runs under a private Xvfb with Mesa's llvmpipe (OpenGL 4.5 core).
if [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
if ! command -v xvfb-run >/dev/null 2>&1; then
  echo "with-display.sh: no DISPLAY and no xvfb-run; install the 'xvfb' package" >&2
  exit 1
fi
# A server number from the PID keeps parallel ctest jobs apart (-a still
# searches upward if that number is taken).
exec xvfb-run -a -n $((100 + $$ % 800)) -s "-screen 0 1280x1024x24 -nolisten tcp" "$@"
