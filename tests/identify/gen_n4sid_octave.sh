#!/usr/bin/env bash
# Regenerates tests/identify/n4sid_octave_cases.inc (data of three systems and
# Octave's n4sid/moesp fits on them) with tests/identify/gen_n4sid_octave.m.
# Needs octave and octave-control (apt-get install -y octave octave-control);
# CI uses the committed .inc and does not run this.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
command -v octave >/dev/null || { echo "error: octave not found (apt-get install -y octave octave-control)" >&2; exit 1; }
octave --no-gui --norc --quiet "$here/gen_n4sid_octave.m" "$here/n4sid_octave_cases.inc" 2>&1 \
  | grep -v "X11 DISPLAY\|disabling GUI\|ignoring const execution_exception"
