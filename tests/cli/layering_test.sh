#!/usr/bin/env bash
# The library's layers (README, CMakeLists.txt): every file of an area
# includes only headers of its own area and of the areas it links, and the
# linear-model layer `lti` knows no model-file schema (tests/cli/layering.py).
# Usage: bash layering_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

"$PY" "$SRC/tests/cli/layering.py" "$SRC" > "$TMP/out" 2>&1 || fail "layering: $(cat "$TMP/out")"
grep -q "^11 areas: common data lti models plant identify" "$TMP/out" ||
  fail "the areas were not read from CMakeLists.txt: $(cat "$TMP/out")"

# The check finds what it is for: an lti file that includes identify and
# reads a model file's "narx".
mkdir -p "$TMP/repo/src/lti"
cp "$SRC/CMakeLists.txt" "$TMP/repo/"
printf '#include "pneumid/identify/identify.hpp"\nconst char* k = "narx";\n' > "$TMP/repo/src/lti/x.cpp"
if "$PY" "$SRC/tests/cli/layering.py" "$TMP/repo" > "$TMP/bad" 2>&1; then
  fail "an upward include passed the check"
fi
grep -q "src/lti/x.cpp:1: area lti includes identify" "$TMP/bad" || fail "upward include not named: $(cat "$TMP/bad")"
grep -q 'src/lti/x.cpp:2: lti reads the model-file key "narx"' "$TMP/bad" || fail "schema key not named: $(cat "$TMP/bad")"
finish
