#!/usr/bin/env bash
# End-to-end test of `pneumid app` in Chromium: the page opens the demo step
# test, identifies three models, tunes an MPC whose metrics must equal
# `pneumid control --json`, runs it 3 s in real time on the simulator with live
# plots, and downloads the log (web/tests/e2e.mjs). Needs node, web/node_modules
# (scripts/setup) and /usr/bin/chromium: without them the test fails.
#
#   bash tests/app/browser_test.sh build/pneumid
#
# PNEUMID_SCREENSHOTS=DIR writes a screenshot of each stage to DIR/app-*.png
# (docs/img holds them); PNEUMID_CHROMIUM=PATH uses another Chromium.
source "$(dirname "${BASH_SOURCE[0]}")/../cli/lib.sh" "$@"

SERVER_PID=""
cleanup() {
  if [ -n "$SERVER_PID" ]; then kill "$SERVER_PID" 2>/dev/null; wait "$SERVER_PID" 2>/dev/null; fi
}

command -v node >/dev/null 2>&1 || die "node not found (Node.js; scripts/setup installs it)"
node -e 'process.exit(Number(process.versions.node.split(".")[0]) >= 20 ? 0 : 1)' ||
  die "node $(node --version) is too old: the page and its test need Node.js 20 or newer"
[ -d "$SRC/web/node_modules/playwright-core" ] ||
  die "$SRC/web/node_modules/playwright-core not found (run scripts/setup, or npm ci in web/)"
[ -x "${PNEUMID_CHROMIUM:-/usr/bin/chromium}" ] ||
  die "${PNEUMID_CHROMIUM:-/usr/bin/chromium} not found (Debian package chromium; scripts/setup installs it)"

if [ -z "${PNEUMID_APP_MOCK:-}" ]; then
  WEB="$(dirname "$PNEUMID")/web"
  [ -f "$WEB/index.html" ] || die "$WEB/index.html not found: the page is not built (it needs npm and \
web/node_modules when CMake configures: run scripts/setup, then cmake and the target pneumid_web)"
  for f in "$SRC"/web/src/* "$SRC/web/index.html"; do
    [ "$f" -nt "$WEB/index.html" ] && fail "$f is newer than $WEB/index.html: rebuild the page (target pneumid_web)"
  done
fi
# the page's TypeScript type-checks
(cd "$SRC/web" && node_modules/.bin/tsc --noEmit -p .) || fail "web/src does not type-check (tsc)"

ROOT="$TMP/root"
mkdir -p "$ROOT"
"$PNEUMID" simulate --plant ipa --input step:from=0.61,to=82,at=1.0 --duration 4 --Ts 0.01 \
  --seed 1 -o "$ROOT/demo.csv" > /dev/null || die "pneumid simulate failed"
# a second file (another step), whose opening must clear the first one's results
"$PNEUMID" simulate --plant ipa --input step:from=20,to=60,at=0.5 --duration 3 --Ts 0.01 \
  --seed 2 -o "$ROOT/step2.csv" > /dev/null || die "pneumid simulate (step2.csv) failed"
"$PNEUMID" identify "$ROOT/demo.csv" -m reaction-curve,arx,fit-p1d -o "$TMP/MODELS.json" \
  > /dev/null || die "pneumid identify failed"
"$PNEUMID" control --controller mpc --rule auto --model "$TMP/MODELS.json#fit-p1d" --plant ipa \
  --Ts 0.01 --setpoint step:from=0,to=40,at=0.5 --duration 10 --json > "$TMP/control.json" ||
  die "pneumid control failed"

TOKEN=e2e-$RANDOM$RANDOM
: > "$TMP/app.txt"
if [ -n "${PNEUMID_APP_MOCK:-}" ]; then
  # the stand-in server of web/tests/mock_server.mjs, for work on the page alone
  node "$SRC/web/tests/mock_server.mjs" "$PNEUMID" --port 0 --root "$ROOT" --token "$TOKEN" \
    --web "$PNEUMID_APP_MOCK" > "$TMP/app.txt" 2>&1 &
else
  "$PNEUMID" app --port 0 --root "$ROOT" --token "$TOKEN" > "$TMP/app.txt" 2>&1 &
fi
SERVER_PID=$!
URL=""
for _ in $(seq 100); do
  URL=$(grep -o 'http://[^ ]*token=[^ ]*' "$TMP/app.txt" | head -n 1)
  [ -n "$URL" ] && break
  kill -0 "$SERVER_PID" 2>/dev/null || break
  sleep 0.1
done
[ -n "$URL" ] || die "pneumid app did not print its address: $(head -c 2000 "$TMP/app.txt")"
echo "pneumid app at $URL"

cp "$ROOT/demo.csv" "$TMP/upload.csv"
node "$SRC/web/tests/e2e.mjs" "$URL" "$TMP/control.json" "$TMP/upload.csv" || fail "the page's end-to-end test (web/tests/e2e.mjs)"
finish
