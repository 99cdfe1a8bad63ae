# lib.sh -- shared by the shell test scripts: pass/fail counting and a check that shows its output on failure.
# The caller sets T (a scratch directory) before calling check.
pass=0
fail=0
ok() { pass=$((pass + 1)); echo "[  PASS  ] $1"; }
ko() { fail=$((fail + 1)); echo "[  FAIL  ] $1"; }
# check "what" command...: runs the command, PASS on exit 0, else FAIL with its output indented
check() { what=$1; shift; if "$@" > "$T/out" 2>&1; then ok "$what"; else ko "$what"; sed 's/^/    /' "$T/out"; fi; }
