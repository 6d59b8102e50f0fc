#!/bin/sh
# Runs a command with an X display for OpenGL: the current one when DISPLAY
# is set (make test runs the whole ctest under one Xvfb), else a private Xvfb
# through xvfb-run (a test run by hand without a display).
if [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
exec xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" "$@"
