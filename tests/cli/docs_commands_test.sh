#!/usr/bin/env bash
# Every `pneumid ...` command line of README.md and docs/*.md still works:
#  - concrete commands in code blocks are run, in document order (README first),
#    in one scratch directory holding the repository's data/, config/ and
#    tests/ folders (the docs run from the repository's root), so that a
#    file written by one command (step.csv) is read by the next;
#  - synopses (with [options], A|B, DATA, FILE, ...), inline `pneumid ...` spans
#    and commands that need a network peer or hardware (udp://, comedi,
#    plant-server) are not run: their command must exist and each flag must
#    be listed by `pneumid COMMAND --help`;
#  - the docs use the canonical flag names (--Ts, --method, -o/--output-dir),
#    not the older spellings kept as aliases.
# Usage: bash docs_commands_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

ln -s "$SRC/data" "$TMP/data"
ln -s "$SRC/config" "$TMP/config"
ln -s "$SRC/tests" "$TMP/tests"
"$PY" - "$SRC" "$PNEUMID" "$TMP" <<'PYEOF' || fail "documented commands (see above)"
import glob, os, re, shlex, subprocess, sys

src, pneumid, work = sys.argv[1:4]
files = [os.path.join(src, "README.md")] + sorted(glob.glob(os.path.join(src, "docs", "*.md")))

# Older spellings kept as aliases: the docs should show the canonical name.
ALIASES = {"--sample-time": "--Ts", "--period": "--Ts", "--methods": "--method",
           "--save": "-o"}
PLACEHOLDER = re.compile(r"(^|[\s=,:])(DATA|MODEL|DIR|FILE|PLANT|SIGNAL|ADDR|HOST|PORT|SPEC|"
                         r"RULE|TS|N|K|X|T|C|S|Y|D|Q|M\d)(\b|$)")
NOT_RUN = re.compile(r"udp://|comedi|plant-server|pneumid app\b")


def commands(path):
    """(line number, command text, in_code_block) of each pneumid command."""
    out = []
    lines = open(path, encoding="utf-8").read().split("\n")
    fenced = False
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.lstrip().startswith("```"):
            fenced = not fenced
            i += 1
            continue
        indented = line.startswith("    ") and not fenced
        text = line.strip()
        if text.startswith("$ "):
            text = text[2:]
        if (fenced or indented) and re.match(r"(pneumid|\$B) ", text):
            start = i + 1
            while text.endswith("\\") and i + 1 < len(lines):
                i += 1
                text = text[:-1] + " " + lines[i].strip()
            out.append((start, re.sub(r"^\$B ", "pneumid ", text), True))
        elif not fenced:
            for span in re.findall(r"`(pneumid [a-z][^`]*)`", line):
                out.append((i + 1, span, False))
        i += 1
    return out


help_cache = {}


def help_text(command):
    if command not in help_cache:
        r = subprocess.run([pneumid, command, "--help"], capture_output=True, text=True)
        help_cache[command] = r.stdout if r.returncode == 0 else None
    return help_cache[command]


failures = 0
ran = 0


def fail(where, message):
    global failures
    failures += 1
    print(f"FAIL: {where}: {message}", file=sys.stderr)


for path in files:
    rel = os.path.relpath(path, src)
    for lineno, text, in_block in commands(path):
        where = f"{rel}:{lineno}: {text}"
        try:
            words = shlex.split(text, comments=True)
        except ValueError as e:
            fail(where, f"cannot split: {e}")
            continue
        words = [w for w in words if w != "&"]
        if len(words) < 2 or not re.match(r"^[a-z][a-z-]*$", words[1]):
            continue
        command = words[1]
        usage = help_text(command)
        if usage is None:
            fail(where, f"'pneumid {command} --help' fails: no such command?")
            continue
        for w in words[2:]:
            for flag in re.findall(r"^(--?[A-Za-z][A-Za-z0-9-]*)", w.split("=")[0])[:1]:
                if flag in ALIASES:
                    fail(where, f"{flag} is an older spelling; write {ALIASES[flag]}")
                elif not re.search(r"(^|[\s,])" + re.escape(flag) + r"([\s,]|$)", usage):
                    fail(where, f"'pneumid {command} --help' does not list {flag}")
        synopsis = ("[" in text or "|" in text.split("#")[0] or "..." in text
                    or PLACEHOLDER.search(text.split("#")[0]))
        if not in_block or synopsis or NOT_RUN.search(text):
            continue
        r = subprocess.run([pneumid] + words[1:], cwd=work, capture_output=True, text=True,
                           timeout=300)
        ran += 1
        if r.returncode != 0:
            fail(where, f"exit {r.returncode}: {r.stderr.strip()[:500]}")

print(f"{ran} documented commands run")
# A parser that stops matching would run nothing and pass: the docs hold 37
# runnable commands (2026-11); fewer than 30 means the parser lost them.
if ran < 30:
    fail("docs", f"only {ran} commands were found and run (at least 30 expected)")
sys.exit(1 if failures else 0)
PYEOF
finish
