#!/usr/bin/env bash
# pneumid paper: the paper's table and Figures 4-6.
# Usage: bash paper_test.sh /path/to/pneumid   (cwd: build directory)
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
WORK=$TMP/work
mkdir "$WORK"

"$PNEUMID" paper -o "$WORK/figs" >"$WORK/out" 2>"$WORK/err" || { cat "$WORK/err"; fail "exit $?"; }
grep -q "paper success" "$WORK/out" || { cat "$WORK/out"; fail "not successful"; }
# the table holds the paper's numbers next to pneumid's
grep -q "6.102 s^2 - 91.95 s + 520000" "$WORK/out" || fail "Eq. 6 row missing"
grep -q "conventional P .* 126 .* 1[0-9][0-9] .*P = round(5 tau'/Ts" "$WORK/out" || fail "conventional P row missing"
grep -q "P, lambda from the paper's FOPDT (Eq. 2) .* 126, 2.25 .* 126, 2.251" "$WORK/out" || fail "P = 126 row missing"
for f in fig4 fig5 fig6; do
  for ext in png svg; do
    [ -s "$WORK/figs/$f.$ext" ] || fail "$f.$ext missing"
  done
  check_png "$WORK/figs/$f.png"
  check_svg "$WORK/figs/$f.svg"
done

"$PNEUMID" paper --json --no-figures >"$WORK/json" || fail "--json failed"
"$PY" - "$WORK/json" <<'PYEOF' || fail "--json output wrong"
import json, sys
d = json.load(open(sys.argv[1]))
rows = d["rows"]
assert len(rows) > 40, len(rows)
for r in rows:
    assert set(r) >= {"quantity", "paper", "pneumid", "note"}, r
q = {r["quantity"]: r for r in rows}
assert q["static gain of Eq. 5 (recomputed)"]["pneumid"] == "1.59796"
assert q["modified P, M, lambda"]["pneumid"] == "126, 10, 1.92"
PYEOF
[ -e figs ] && fail "--no-figures wrote files"

"$PNEUMID" paper --ipa-config "$WORK/none.toml" 2>"$WORK/err" && fail "missing config accepted"
grep -q "none.toml" "$WORK/err" || fail "error does not name the config file"
check_help paper "-o,--output-dir"
finish
