#!/usr/bin/env bash
# CLI tests of `pneumid app`: the HTTP JSON API of docs/app.md through Python's
# standard library (urllib, a socket for the oversized upload and the WebSocket).
# Usage: bash app_test.sh /path/to/pneumid   (cwd: a scratch/build directory)
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
APP_PID=""
cleanup() {  # called by lib.sh on exit
  if [ -n "$APP_PID" ]; then kill "$APP_PID" 2>/dev/null; wait "$APP_PID" 2>/dev/null; fi
}

check_help app --port --host --root --open --assets --token --allow-remote --allow-device
expect_error "remote host" "add --allow-remote" app --host 0.0.0.0 --port 0

ROOT="$TMP/root"
mkdir -p "$ROOT/sub"
ln -s /etc "$ROOT/link"
"$PNEUMID" simulate --plant ipa --input step:from=0.61,to=82,at=1.0 --duration 4 --Ts 0.01 \
  --seed 1 -o "$ROOT/demo.csv" > /dev/null || die "simulate the demo step test"
(cd "$ROOT" && "$PNEUMID" identify demo.csv -m reaction-curve,arx,fit-p1d -o models.json \
  > /dev/null) || die "identify -o models.json"
(cd "$ROOT" && "$PNEUMID" control --controller dmc --model 'models.json#arx' --plant ipa \
  --Ts 0.01 --setpoint step:from=0,to=80,at=0.5 --duration 3 --load-step at=2,size=-10 \
  --json > "$TMP/control_cli.json") || fail "control --json"
# Python's simulate_control runs the same library scenario as `control`: the
# same JSON, number for number (the app's is compared below).
PY_MODULE_DIR="$(dirname "$PNEUMID")/python"
if compgen -G "$PY_MODULE_DIR/pneumid*.so" > /dev/null; then
  (cd "$ROOT" && PYTHONPATH="$PY_MODULE_DIR" "$PY" - "$TMP/control_cli.json" <<'EOF'
import json, sys
import pneumid
cli = json.load(open(sys.argv[1]))
py = pneumid.simulate_control("models.json#arx", plant="ipa", Ts=0.01,
                              setpoint="step:from=0,to=80,at=0.5", duration=3,
                              load_steps=[(2.0, -10.0)], type="dmc")
if py != cli:
    diff = {k: (py.get(k), cli.get(k)) for k in set(py) | set(cli) if py.get(k) != cli.get(k)}
    sys.exit(f"simulate_control differs from control --json: {diff}")
if not (cli["iae"] > 0 and len(cli["steps"]) >= 1):
    sys.exit(f"control --json without metrics: {cli}")
EOF
  ) || fail "python simulate_control = control --json"
else
  echo "note: no Python module in $PY_MODULE_DIR; the Python leg is skipped"
fi
(cd "$ROOT" && "$PNEUMID" identify demo.csv -m reaction-curve,arx,fit-p1d --detrend none \
  --json > "$TMP/identify_cli.json") || fail "identify --json"
"$PNEUMID" tune --model fopdt-paper --Ts 0.01 --json > "$TMP/tune_cli.json" || fail "tune --json"
rc=0
# The app's Commission takes the command's default loop period (on the IPA
# its PWM period, DefaultLoopPeriod): the request gives no Ts.
"$PNEUMID" commission --plant ipa --budget 40 -o "$TMP/comm" --json > "$TMP/commission_cli.json" || rc=$?
[ "$rc" -eq 0 ] || [ "$rc" -eq 4 ] || fail "commission --json exited $rc"
"$PNEUMID" tune --rule auto --model fopdt-paper --Ts 0.01 --plant ipa --json > "$TMP/tune_auto_cli.json" ||
  fail "tune --rule auto --plant ipa --json"

# start_app LOG [OPTIONS...]: pneumid app on a free port under $ROOT in the
# background (APP_PID); URL is the address it prints ("" when none in 10 s).
start_app() {
  local log=$1
  shift
  : > "$log"  # empty before the job starts (its redirection may come late)
  "$PNEUMID" app --port 0 --root "$ROOT" "$@" > "$log" 2>&1 &
  APP_PID=$!
  URL=""
  for _ in $(seq 100); do
    URL=$(grep -o 'http://127\.0\.0\.1:[0-9]*/?token=[0-9a-z]*' "$log" | head -1)
    [ -n "$URL" ] && break
    sleep 0.1
  done
}

# Empty the file before the background job starts (its redirection may come late).
: > "$TMP/app.txt"
mkdir -p "$TMP/apptmp"  # the app's temporary folder goes here (checked below)
TMPDIR="$TMP/apptmp" "$PNEUMID" app --port 0 --root "$ROOT" --assets "$TMP/no-assets" \
  --token secret123 > "$TMP/app.txt" 2>&1 &
APP_PID=$!
URL=""
for _ in $(seq 100); do
  URL=$(sed -n 's/^pneumid app: serving.*\(http:\/\/127\.0\.0\.1:[0-9]*\/?token=[0-9a-z]*\).*/\1/p' \
    "$TMP/app.txt")
  [ -n "$URL" ] && break
  sleep 0.1
done
[ -n "$URL" ] || die "pneumid app did not print its address: $(cat "$TMP/app.txt")"
grep -q "token=secret123" <<< "$URL" || fail "the address lacks the token: $URL"
BASE=${URL%%/\?token=*}

cat > "$TMP/client.py" << 'EOF'
import base64, json, os, socket, sys, time, urllib.error, urllib.request

base, token, tmp = sys.argv[1], sys.argv[2], sys.argv[3]
failures = []

def fail(msg):
    print("FAIL: " + msg, file=sys.stderr)
    failures.append(msg)

def call(method, path, body=None, headers=None, with_token=True, raw=False):
    headers = dict(headers or {})
    if with_token:
        headers.setdefault("X-Pneumid-Token", token)
    data = None
    if body is not None:
        data = body if isinstance(body, bytes) else json.dumps(body).encode()
        headers.setdefault("Content-Type", "application/json")
    req = urllib.request.Request(base + path, data=data, method=method, headers=headers)
    try:
        with urllib.request.urlopen(req, timeout=120) as r:
            status, text = r.status, r.read().decode()
    except urllib.error.HTTPError as e:
        status, text = e.code, e.read().decode()
    if raw:
        return status, text
    try:
        return status, json.loads(text)
    except ValueError:
        return status, text

def expect(status, answer, want, what):
    if status != want:
        fail(f"{what}: HTTP {status} (expected {want}): {str(answer)[:300]}")
        return False
    return True

# --- security: the token on every path, the origin, the root
for path in ["/", "/assets/index.js", "/api/version"]:
    s, a = call("GET", path, with_token=False)
    expect(s, a, 403, f"GET {path} without a token")
    s, a = call("GET", path, with_token=False, headers={"X-Pneumid-Token": "wrong"})
    expect(s, a, 403, f"GET {path} with a wrong token")
s, a = call("GET", "/api/version?token=" + token, with_token=False)
if expect(s, a, 200, "token as a query parameter") and a.get("version") is None:
    fail(f"version: {a}")
s, a = call("GET", "/api/version", headers={"Origin": "http://evil.example"})
expect(s, a, 403, "a foreign Origin")
s, a = call("GET", "/api/version", headers={"Origin": base})
expect(s, a, 200, "the server's own Origin")
s, a = call("GET", "/api/version", headers={"Host": "evil.example:80"})
expect(s, a, 403, "a foreign Host header (DNS rebinding)")
req = urllib.request.Request(base + "/api/version", headers={"X-Pneumid-Token": token})
with urllib.request.urlopen(req, timeout=30) as r:
    csp = r.headers.get("Content-Security-Policy", "")
    if "frame-ancestors 'none'" not in csp or r.headers.get("X-Frame-Options") != "DENY":
        fail(f"no CSP / X-Frame-Options: {csp!r} {r.headers.get('X-Frame-Options')!r}")
s, a = call("GET", "/", raw=True)
if expect(s, a, 200, "GET / without assets") and "not built" not in a:
    fail("GET / without assets does not say the front end was not built")
s, a = call("POST", "/api/data/open", {"path": "../../etc/passwd"})
if expect(s, a, 403, "open ../../etc/passwd") and "outside the root" not in a.get("error", ""):
    fail(f"open ../../etc/passwd: {a}")
s, a = call("POST", "/api/data/open", {"path": "/etc/passwd"})
expect(s, a, 403, "open an absolute path outside the root")
s, a = call("GET", "/api/files?dir=..")
expect(s, a, 403, "list the root's parent")
s, a = call("POST", "/api/data/open", {"path": "link/passwd"})
expect(s, a, 403, "open through a symbolic link that leaves the root")
s, a = call("POST", "/api/control", {"model": "../x.json", "setpoint": "step:to=1", "duration": 1})
expect(s, a, 403, "a model file outside the root")
# Every path-like field is confined, and no content of a file outside leaks.
outside = os.path.join(tmp, "outside.csv")
with open(outside, "w") as f:
    f.write("t,u\n0,31337.25\n0.01,31337.25\n")
secret_toml = os.path.join(tmp, "outside.toml")
with open(secret_toml, "w") as f:
    f.write("[secret_section]\nsecret_key_name = 1\n")
ctl = {"model": "fopdt-paper", "Ts": 0.01, "duration": 0.2}
# The kind in any case and blanks around it (as the signal parser reads it):
# "FILE:", "File :" and a leading newline read the outside file before.
for sp in ["file:" + outside + ",col=u", "file:../outside.csv,col=u", "  file:" + outside,
           "FILE:" + outside + ",col=u", "File :../outside.csv,col=u", "\nfile:" + outside,
           "file: " + outside]:
    s, a = call("POST", "/api/control", dict(ctl, setpoint=sp))
    if expect(s, a, 403, f"a set-point file outside the root ({sp})") and "31337" in str(a):
        fail(f"the outside file's values leak: {str(a)[:200]}")
for plant in ["ipa:config=/etc/shadow", "ipa:config=" + secret_toml, "ipa-position:mode=position,config=../outside.toml"]:
    s, a = call("POST", "/api/control", dict(ctl, setpoint="step:to=50", plant=plant))
    if expect(s, a, 403, f"a plant configuration outside the root ({plant})") and "secret" in str(a):
        fail(f"the outside TOML's keys leak: {str(a)[:200]}")
s, a = call("POST", "/api/run/start", {"model": "fopdt-paper", "io": "comedi:/dev/null",
                                       "setpoint": "step:to=1", "duration": 0.5})
expect(s, a, 403, "a device not allowed on the command line")
# An unknown controller is refused at the start, not in the run's status.
s, a = call("POST", "/api/run/start", {"model": "fopdt-paper", "controller": "nope",
                                       "setpoint": "step:to=1", "duration": 0.5})
expect(s, a, 400, "run/start with an unknown controller")
s, a = call("POST", "/api/control", dict(ctl, setpoint="file:demo.csv\u0000x,col=u"))
expect(s, a, 400, "a NUL byte in a path")
s, a = call("POST", "/api/control", dict(ctl, setpoint="file:" + "a/" * 3000 + "x.csv"))
if expect(s, a, 400, "an over-long path") and len(str(a)) > 1000:
    fail(f"the over-long path is echoed whole: {len(str(a))} characters")
# A set-point file under the root is read.
s, a = call("POST", "/api/control", dict(ctl, setpoint="file:demo.csv,col=u", plant="ipa"))
expect(s, a, 200, "a set-point file under the root")

# --- idle connections cannot hold the server: 40 sockets that send nothing
# (the limit is 32 connections), then a request is still answered, and a
# socket that sends nothing is closed by the server within the header deadline.
import socket as _socket
host, port = base.split("//")[1].split(":")
idle = []
for _ in range(40):
    c = _socket.create_connection((host, int(port)), timeout=5)
    idle.append(c)
time.sleep(0.5)
s, a = call("GET", "/api/version")
expect(s, a, 200, "a request while 40 idle connections are open")
probe = idle[-1]
probe.settimeout(15)
try:
    closed = probe.recv(1) == b""
except OSError:
    closed = True
if not closed:
    fail("an idle connection was not closed by the server")
for c in idle:
    c.close()

# --- malformed HTTP gets a status before the connection closes
def raw_status(raw):
    c = _socket.create_connection((host, int(port)), timeout=10)
    c.sendall(raw)
    data = b""
    try:
        while True:
            d = c.recv(65536)
            if not d:
                break
            data += d
    except OSError:
        pass
    c.close()
    return data.split(b"\r\n")[0].decode(errors="replace")
hdr = f"Host: {host}:{port}\r\nX-Pneumid-Token: {token}\r\n"
for raw, want, what in [
        (f"POST /api/tune HTTP/1.1\r\n{hdr}Content-Length: abc\r\n\r\n", " 400 ", "a bad Content-Length"),
        (f"POST /api/tune HTTP/1.1\r\n{hdr}Transfer-Encoding: chunked\r\n\r\nzz\r\nxx\r\n", " 400 ", "a bad chunk"),
        (f"GET /api/version HTTP/1.1\r\n{hdr}X-Big: {'a' * 100000}\r\n\r\n", " 431 ", "a 100 kB header")]:
    line = raw_status(raw.encode())
    if want not in line:
        fail(f"{what}: answered {line!r} (expected{want.rstrip()})")

# --- files and data
s, a = call("GET", "/api/files")
if expect(s, a, 200, "files"):
    names = {(e["name"], e["type"]) for e in a["entries"]}
    if ("demo.csv", "file") not in names or ("sub", "dir") not in names:
        fail(f"files: {a}")
    if any(e["name"] == "link" for e in a["entries"]):
        fail(f"the listing shows a link that leaves the root: {a}")
s, a = call("POST", "/api/data/open", {"path": "demo.csv"})
data_id = None
if expect(s, a, 200, "open demo.csv"):
    data_id = a["id"]
    for key in ["name", "columns", "t", "u", "y", "samples", "Ts", "signals"]:
        if key not in a:
            fail(f"data set lacks {key}")
    if a["samples"] != 401 or len(a["signals"]["y"]) != 401:
        fail(f"data set: {a['samples']} samples, {len(a['signals']['y'])} drawn")
s, a = call("POST", "/api/data/open", {"path": "missing.csv"})
expect(s, a, 404, "open a missing file")

# an upload within the limit
with open(os.path.join(os.path.dirname(tmp + "/"), "root", "demo.csv"), "rb") as f:
    demo = f.read()
s, a = call("POST", "/api/data/upload?name=up.csv", demo,
            headers={"Content-Type": "application/octet-stream"})
if expect(s, a, 200, "upload") and a.get("samples") != 401:
    fail(f"upload: {a}")
# A bad upload is named as the client named it, not by the app's folder.
s, a = call("POST", "/api/data/upload?name=empty.csv", b"",
            headers={"Content-Type": "application/octet-stream"})
if expect(s, a, 422, "an empty upload") and (
        "empty.csv" not in a.get("error", "") or "pneumid-app" in a.get("error", "")):
    fail(f"the empty upload's error: {a}")

# a 100 MB upload: refused from its Content-Length, before the body is read
host, port = base[len("http://"):].split(":")
sock = socket.create_connection((host, int(port)), timeout=30)
size = 100 * 1024 * 1024
sock.sendall((f"POST /api/data/upload?name=big.csv HTTP/1.1\r\nHost: {host}:{port}\r\n"
              f"X-Pneumid-Token: {token}\r\nContent-Length: {size}\r\n\r\n").encode())
try:
    sock.sendall(b"\0" * 65536)
except OSError:
    pass
reply = b""
while True:
    try:
        chunk = sock.recv(65536)
    except OSError:
        break
    if not chunk:
        break
    reply += chunk
sock.close()
head, _, body = reply.partition(b"\r\n\r\n")
if not head.startswith(b"HTTP/1.1 413"):
    fail(f"100 MB upload: {head[:100]!r}")
elif f"upload of {size} bytes is larger than the 50 MB limit".encode() not in body:
    fail(f"100 MB upload message: {body[:200]!r}")

# --- identify: the command line's JSON, plus responses and the model file
methods = ["reaction-curve", "arx", "fit-p1d"]
s, a = call("POST", "/api/identify", {"data": data_id, "methods": methods, "detrend": "none"})
if expect(s, a, 200, "identify"):
    cli = json.load(open(tmp + "/identify_cli.json"))
    responses = a.pop("responses")
    model_file = a.pop("model_file")
    if a != cli:
        fail("identify: not the JSON of pneumid identify --json")
    if model_file != cli:
        fail("identify: model_file differs from pneumid identify --json")
    for m in methods + ["t"]:
        if m not in responses or len(responses[m] or []) != 401:
            fail(f"identify: no response of {m}")
    arx = next(m for m in model_file["models"] if m["method"] == "arx")
s, a = call("POST", "/api/identify", {"data": "d99", "methods": methods})
expect(s, a, 404, "identify an unknown data set")
# the nonlinear methods through the same call
s, a = call("POST", "/api/identify", {"data": data_id, "methods": ["hammerstein", "affine-narx"]})
if expect(s, a, 200, "identify nonlinear"):
    got = sorted(m["method"] for m in a["models"])
    if got != ["affine-narx", "hammerstein"] or any(m["fit_percent"] < 90 for m in a["models"]):
        fail(f"identify nonlinear: {[(m['method'], m['fit_percent']) for m in a['models']]}")
# a validation record whose input holds one level: still ranked, with the
# command line's warning in "warnings"
flat = []
for line in demo.decode().splitlines():
    cells = line.split(",")
    if line.startswith("#") or not cells[0][:1].isdigit():
        flat.append(line)
    else:
        cells[1] = "50"
        flat.append(",".join(cells))
s, a = call("POST", "/api/data/upload?name=flat.csv", ("\n".join(flat) + "\n").encode(),
            headers={"Content-Type": "application/octet-stream"})
if expect(s, a, 200, "upload a record at one input level"):
    s, a = call("POST", "/api/identify", {"data": data_id, "methods": ["arx", "fit-p1d"],
                                          "validation": a["id"], "detrend": "none"})
    if expect(s, a, 200, "identify with a validation record at one input level"):
        w = a.get("warnings", [])
        if len(w) != 1 or "holds a constant input (u = 50 over 401 samples)" not in w[0]:
            fail(f"identify on a one-level validation record: warnings {w}")

# --- views of a model: step, Bode, the fit and residual correlations on data
s, a = call("POST", "/api/model/views", {"model": arx, "data": data_id, "validation": data_id})
if expect(s, a, 200, "model views"):
    if abs(a["estimation"]["fit_percent"] - a["validation"]["fit_percent"]) > 1e-9:
        fail("model views: the same data set gives two fits")
    # ARX fits the demo step test above 95 % (the command line's identify says the same)
    if not a["estimation"]["fit_percent"] > 95:
        fail(f"model views: fit {a['estimation']['fit_percent']}")
    r = a["estimation"]["residuals"]
    if r["autocorr"][0] != 1.0 or len(r["cross_lags"]) != 2 * len(r["auto_lags"]) - 1:
        fail(f"model views: residual correlations {str(r)[:200]}")
    if len(a["step"]["t"]) < 10 or len(a["bode"]["omega"]) < 10:
        fail("model views: no step or Bode data")
s, a = call("POST", "/api/model/views", {"model": "models.json#arx", "data": data_id})
expect(s, a, 400, "model views with a spec instead of a model object")
s, a = call("POST", "/api/model/views", {"model": arx, "data": "d99"})
expect(s, a, 404, "model views on an unknown data set")

# --- tune and control: the command line's JSON
s, a = call("POST", "/api/tune", {"model": "fopdt-paper", "Ts": 0.01})
if expect(s, a, 200, "tune") and a != json.load(open(tmp + "/tune_cli.json")):
    fail("tune: not the JSON of pneumid tune --json")
# the rule auto with the loop's plant: designed within its input range, as tune --plant
s, a = call("POST", "/api/tune", {"model": "fopdt-paper", "Ts": 0.01, "rule": "auto",
                                  "plant": "ipa"})
if expect(s, a, 200, "tune auto") and a != json.load(open(tmp + "/tune_auto_cli.json")):
    fail("tune auto with a plant: not the JSON of pneumid tune --rule auto --plant ipa --json")
scenario = {"controller": "dmc", "plant": "ipa", "Ts": 0.01, "duration": 3,
            "setpoint": "step:from=0,to=80,at=0.5", "load_step": "at=2,size=-10"}
s, a = call("POST", "/api/control", dict(scenario, model="models.json#arx"))
if expect(s, a, 200, "control"):
    trace = a.pop("trace")
    # What control prints on stderr (none for a linear model) comes as "warnings",
    # as in control --json.
    if a.get("warnings") != []:
        fail("control: no 'warnings' list, or one where pneumid control warns of nothing")
    cli = json.load(open(tmp + "/control_cli.json"))
    if a.pop("steps_total", None) != len(a.get("steps", [])):
        fail("control: no 'steps_total', or not the number of steps listed")
    if a != cli:
        fail(f"control: not the JSON of pneumid control --json:\n{a}\n{cli}")
    if len(trace["y"]) != len(trace["t"]) or len(trace["t"]) < 300:
        fail(f"control trace: {len(trace['t'])} points")
# a model object (an entry of the model file) gives the same metrics
s, a = call("POST", "/api/control", dict(scenario, model=arx))
if expect(s, a, 200, "control with a model object"):
    cli = json.load(open(tmp + "/control_cli.json"))
    for key in ["iae", "rise_time", "overshoot_percent", "settling_time"]:
        if a.get(key) != cli.get(key):
            fail(f"control with a model object: {key} {a.get(key)} != {cli.get(key)}")
import glob
left = glob.glob(tmp + "/apptmp/pneumid-app-*/model*.json")
if left:
    fail(f"a request's model object is left in the temporary folder: {left}")
if not glob.glob(tmp + "/apptmp/pneumid-app-*"):
    fail("the app's temporary folder is not under TMPDIR")
# Numbers: integers are integers in range, Ts and the samples are bounded.
for bad, what in [({"P": 1e308}, "P = 1e308"), ({"P": 2.5}, "P = 2.5"), ({"M": -3e9}, "M = -3e9"),
                  ({"Ts": 1e-300}, "Ts = 1e-300"), ({"duration": 1e9}, "duration = 1e9"),
                  ({"Ts": 1e-6, "controller": "dmc"}, "Ts = 1e-6"), ({"P": 100000}, "P = 1e5")]:
    s, a = call("POST", "/api/control", dict(scenario, model="fopdt-paper", **bad))
    expect(s, a, 422, f"control with {what}")
# PID gains given explicitly replace the rule's
s, a = call("POST", "/api/control", dict(scenario, model="fopdt-paper", controller="pid", Kc=5.0))
if expect(s, a, 200, "control pid with Kc") and (a["settings"]["Kc"] != 5.0 or
                                                  a["settings"]["rule"] != "explicit"):
    fail(f"control pid with Kc: {a['settings']}")
s, a = call("POST", "/api/control", dict(scenario, model="fopdt-paper", controller="pid", Ti=-1))
expect(s, a, 400, "control pid with Ti = -1")
for bad in [{"controller": "foo"}, {"controller": ["dmc"]}]:
    s, a = call("POST", "/api/tune", {"model": "fopdt-paper", **bad})
    if s == 200:
        fail(f"tune accepts {bad}: {str(a)[:200]}")
s, a = call("POST", "/api/control", {"model": "fopdt-paper", "duration": 1})
if expect(s, a, 400, "control without a set point") and "setpoint" not in a.get("error", ""):
    fail(f"control without a set point: {a}")
s, a = call("POST", "/api/control", b"{not json")
expect(s, a, 400, "a body that is not JSON")

# --- commission: the command's JSON, the files under the root, the limits
s, a = call("POST", "/api/commission", {"plant": "ipa", "budget": 40, "dir": "comm"})
if expect(s, a, 200, "commission"):
    cli = json.load(open(tmp + "/commission_cli.json"))
    for key in ["termination", "chosen_model", "plant_time", "passed"]:
        if a.get(key) != cli.get(key):
            fail(f"commission: {key} {a.get(key)} != the command's {cli.get(key)}")
    for key in ["overshoot_percent", "settling_time", "iae"]:
        if a["verification"].get(key) != cli["verification"].get(key):
            fail(f"commission: verification {key} {a['verification'].get(key)} != "
                 f"{cli['verification'].get(key)}")
    if a.get("directory") != "comm" or not os.path.isfile(tmp + "/root/comm/controller.toml"):
        fail(f"commission: files not in root/comm: {a.get('files')}")
    if "[controller]" not in a.get("controller_toml", ""):
        fail("commission: no controller_toml")
    if len(a["trace"]["t"]) < 100 or len(a["experiment_trace"]["y"]) < 100:
        fail("commission: traces missing")
for bad, code in [({"dir": "../out"}, 403), ({"budget": 1e9}, 422), ({"budget": -1}, 422),
                  ({"controller": "foo"}, 400), ({"range": [10]}, 400),
                  ({"plant": "ipa:config=/etc/passwd"}, 403)]:
    s, a = call("POST", "/api/commission", bad)
    expect(s, a, code, f"commission with {bad}")
s, a = call("POST", "/api/commission", {"range": [10, 400], "budget": 30})
if expect(s, a, 200, "commission out of reach") and (
        a.get("termination") != "failure" or "cannot be reached" not in a.get("message", "")):
    fail(f"commission out of reach: {a.get('termination')}: {a.get('message')}")

# --- exports
s, a = call("POST", "/api/export/controller", dict(scenario, model="models.json#arx"), raw=True)
if expect(s, a, 200, "export controller"):
    open(tmp + "/controller.toml", "w").write(a)
# The PID's gains go on the exported command line (they were dropped: the
# exported run used the rule's PID).
s, a = call("POST", "/api/export/controller",
            dict(scenario, model="fopdt-paper", controller="pid", Kc=2, Ti=0.3, Td=0.01,
                 tau_c=0.2), raw=True)
if expect(s, a, 200, "export a PID") and not ("--Kc 2 --Ti 0.3 --Td 0.01" in a and
                                                "tau_c = 0.2" in a):
    fail(f"export: the PID's gains are not in the exported configuration:\n{a}")
# A long dead time at a short Ts is refused before the MPC's design (1200
# states took 18 s past a 2 s deadline).
s, a = call("POST", "/api/control", {"model": "fopdt:K=1.6,tau=0.25,theta=12", "controller": "mpc",
                                     "Ts": 0.01, "duration": 2, "setpoint": "step:to=40"})
if expect(s, a, 422, "a model of 1201 states") and "1201 states" not in a.get("error", ""):
    fail(f"the long dead time's error does not name the states: {a}")
s, a = call("POST", "/api/export/report", {"data": data_id, "methods": methods}, raw=True)
if expect(s, a, 200, "export report") and "<html" not in a.lower():
    fail("export report: not HTML")

# --- real-time run: start, 409, status, live stream, stop, log
def ws_connect(path):
    sock = socket.create_connection((host, int(port)), timeout=30)
    key = base64.b64encode(os.urandom(16)).decode()
    sock.sendall((f"GET {path}?token={token} HTTP/1.1\r\nHost: {host}:{port}\r\n"
                  "Upgrade: websocket\r\nConnection: Upgrade\r\n"
                  f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n").encode())
    buf = b""
    while b"\r\n\r\n" not in buf:
        chunk = sock.recv(4096)
        if not chunk:
            break
        buf += chunk
    head, _, rest = buf.partition(b"\r\n\r\n")
    return sock, head, rest

def ws_frames(sock, rest):
    buf = rest
    def need(n):
        nonlocal buf
        while len(buf) < n:
            chunk = sock.recv(65536)
            if not chunk:
                raise EOFError
            buf += chunk
    while True:
        need(2)
        op, n = buf[0] & 0x0F, buf[1] & 0x7F
        off = 2
        if n == 126:
            need(4); n = int.from_bytes(buf[2:4], "big"); off = 4
        elif n == 127:
            need(10); n = int.from_bytes(buf[2:10], "big"); off = 10
        need(off + n)
        payload, buf = buf[off:off + n], buf[off + n:]
        if op == 1:
            yield json.loads(payload)
        elif op == 8:
            return

# (overruns tolerated: the test machine may be busy)
run = {"controller": "dmc", "model": "fopdt-paper", "io": "sim", "Ts": 0.01, "duration": 1,
       "setpoint": "step:from=0,to=100,at=0.2", "max_overruns": -1}
s, a = call("POST", "/api/run/start", run)
if expect(s, a, 200, "run start") and a.get("state") != "running":
    fail(f"run start: {a}")
s, a = call("POST", "/api/run/start", run)
expect(s, a, 409, "a second run while one is going on")
s, a = call("GET", "/api/run/status")
if expect(s, a, 200, "run status") and a.get("state") not in ("running", "finished"):
    fail(f"run status: {a}")
sock, head, rest = ws_connect("/api/run/stream")
if not head.startswith(b"HTTP/1.1 101"):
    fail(f"stream: no WebSocket: {head[:200]!r}")
else:
    samples, summary = 0, None
    for frame in ws_frames(sock, rest):
        if frame.get("done"):
            summary = frame.get("summary")
            break
        if len(frame["t"]) != len(frame["y"]):
            fail("stream: a batch of unequal lengths")
        samples += len(frame["t"])
    if summary is None or samples != 100 or summary.get("samples") != 100:
        fail(f"stream: {samples} samples, summary {summary}")
sock.close()
s, a = call("POST", "/api/run/stop")
if expect(s, a, 200, "run stop") and a.get("termination") != "success":
    fail(f"run stop after the end: {a}")
s, a = call("GET", "/api/run/log", raw=True)
if expect(s, a, 200, "run log"):
    rows = [l for l in a.splitlines() if l and not l.startswith("#")]
    if rows[0] != "t,u,y,r,u_ctrl,aux,jitter_us,compute_us,flags,fault" or len(rows) != 101:
        fail(f"run log: {len(rows)} lines, header {rows[0]}")
# a longer run stopped early: the plant goes to its safe state
s, a = call("POST", "/api/run/start", dict(run, duration=30))
expect(s, a, 200, "run start (30 s)")
time.sleep(0.5)
s, a = call("POST", "/api/run/stop")
if expect(s, a, 200, "run stop") and a.get("termination") != "stopped":
    fail(f"run stop: {a}")
s, a = call("GET", "/api/run/status")
if a.get("state") != "stopped":
    fail(f"status after stop: {a}")
# a run going on when the server is told to stop (SIGINT below)
s, a = call("POST", "/api/run/start", dict(run, duration=30))
expect(s, a, 200, "run start before SIGINT")
sys.exit(1 if failures else 0)
EOF

$PY "$TMP/client.py" "$BASE" secret123 "$TMP" || fail "API checks (above)"

# the exported configuration is one `pneumid run --config` reads
if [ -s "$TMP/controller.toml" ]; then
  "$PNEUMID" run --config "$TMP/controller.toml" --model fopdt-paper --fast --duration 0.5 \
    --json > "$TMP/run_config.json" || fail "run --config the exported TOML: $(cat "$TMP/run_config.json")"
fi

# SIGINT (Ctrl-C) with a run going on: the run stops, the server exits 0
kill -INT "$APP_PID"
rc=0
wait "$APP_PID" || rc=$?
APP_PID=""
[ "$rc" -eq 0 ] || fail "pneumid app exit status after SIGINT: $rc: $(cat "$TMP/app.txt")"
grep -q "stopping" "$TMP/app.txt" || fail "pneumid app did not say it stops: $(cat "$TMP/app.txt")"

# The page from --assets, with the cookie that lets its assets load; SIGTERM ends it
mkdir -p "$TMP/web/assets"
echo '<!doctype html><script type="module" src="./assets/app.js"></script>' > "$TMP/web/index.html"
echo 'console.log("pneumid");' > "$TMP/web/assets/app.js"
echo 'top-secret-content' > "$TMP/web/secret.txt"
start_app "$TMP/app.txt" --assets "$TMP/web"
grep -q 'http://127\.0\.0\.1:[0-9]*/?token=[0-9a-f]\{32\}$' "$TMP/app.txt" || URL=""
[ -n "$URL" ] || fail "no address with a 32-digit random token: $(cat "$TMP/app.txt")"
if [ -n "$URL" ]; then
  $PY - "$URL" << 'PYEOF' || fail "page and assets (above)"
import sys, urllib.error, urllib.request
base, token = sys.argv[1].split("/?token=")
bad = 0
def get(path, headers=None):
    try:
        with urllib.request.urlopen(urllib.request.Request(base + path, headers=headers or {})) as r:
            return r.status, r.read().decode(), r.headers
    except urllib.error.HTTPError as e:
        return e.code, e.read().decode(), e.headers
def check(ok, msg):
    global bad
    if not ok:
        print("FAIL: " + msg, file=sys.stderr)
        bad += 1
s, body, headers = get("/?token=" + token)
cookie = headers.get("Set-Cookie", "")
check(s == 200 and "./assets/app.js" in body and "HttpOnly" in cookie,
      f"GET /: {s} {body[:100]} cookie {cookie}")
jar = {"Cookie": cookie.split(";")[0]}
s, body, headers = get("/assets/app.js", jar)
check(s == 200 and "pneumid" in body and "javascript" in headers.get("Content-Type", ""),
      f"an asset with the cookie: {s} {body[:100]}")
s, body, _ = get("/assets/app.js")
check(s == 403, f"an asset without a token: {s}")
s, body, _ = get("/assets/%2e%2e/secret.txt", jar)
check(s == 403 and "top-secret-content" not in body, f"a file outside the assets folder: {s} {body[:100]}")
sys.exit(1 if bad else 0)
PYEOF
fi
kill -TERM "$APP_PID"
rc=0
wait "$APP_PID" || rc=$?
APP_PID=""
[ "$rc" -eq 0 ] || fail "pneumid app exit status after SIGTERM: $rc"

# Long requests: stopped when the client leaves, answered 503 after the
# deadline, and SIGTERM during one ends the app within about a second, its
# temporary folder removed.
mkdir -p "$TMP/apptmp2"
TMPDIR="$TMP/apptmp2" start_app "$TMP/app2.txt" --assets "$TMP/no-assets" --token t2 \
  --request-deadline 4
URL2=${URL%%/\?token=*}
[ -n "$URL" ] || die "the second app did not start: $(cat "$TMP/app2.txt")"
LONG="$(dirname "${BASH_SOURCE[0]}")/app_long_request.py"
APP2_PID=$APP_PID
"$PY" "$LONG" "$URL2" "$APP2_PID" t2 leave || fail "a request whose client leaves"
"$PY" "$LONG" "$URL2" "$APP2_PID" t2 deadline 4 || fail "the request deadline"
# 2e6 samples of a constrained DMC with P = 5000: about 15 s of work, within the limits.
"$PY" -c "
import json, sys, urllib.request
req = urllib.request.Request(sys.argv[1] + '/api/control', method='POST',
    data=json.dumps({'model': 'fopdt-paper', 'controller': 'dmc', 'P': 5000, 'M': 5, 'lambda': 1,
                     'constrained': True, 'u_min': 0, 'u_max': 100,
                     'Ts': 0.0001, 'duration': 199, 'setpoint': 'step:to=1'}).encode(),
    headers={'X-Pneumid-Token': 't2', 'Content-Type': 'application/json'})
try:
    urllib.request.urlopen(req, timeout=60)
except Exception:
    pass
" "$URL2" &
CLIENT_PID=$!
sleep 1
"$PY" "$LONG" "$URL2" "$APP2_PID" t2 busy || fail "the long request before SIGTERM"
start=$(date +%s%N)
kill -TERM "$APP_PID"
wait "$APP_PID" 2>/dev/null
elapsed_ms=$(( ($(date +%s%N) - start) / 1000000 ))
APP_PID=""
kill "$CLIENT_PID" 2>/dev/null; wait "$CLIENT_PID" 2>/dev/null
echo "SIGTERM during a long request: the app ended in $elapsed_ms ms"
[ "$elapsed_ms" -lt 3000 ] || fail "the app took $elapsed_ms ms to end after SIGTERM during a request"
if ls -d "$TMP"/apptmp2/pneumid-app-* >/dev/null 2>&1; then
  fail "the app's temporary folder is left after SIGTERM: $(ls "$TMP/apptmp2")"
fi

finish
