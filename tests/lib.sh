# lib.sh -- shared by the shell test scripts: pass/fail counting and a check that shows its output on failure.
# The caller sets T (a scratch directory) before calling check.
pass=0
fail=0
ok() { pass=$((pass + 1)); echo "[  PASS  ] $1"; }
ko() { fail=$((fail + 1)); echo "[  FAIL  ] $1"; }
# check "what" command...: runs the command, PASS on exit 0, else FAIL with its output indented
check() { what=$1; shift; if "$@" > "$T/out" 2>&1; then ok "$what"; else ko "$what"; sed 's/^/    /' "$T/out"; fi; }
# need_netns SUITE WHAT: ends the suite, failed, when unshare -rn (a network namespace of its own, for WHAT) is not allowed
need_netns() {
    unshare -rn true 2> /dev/null && return 0
    ko "$1: unshare -rn ($2) is not allowed here"
    echo "$1: $pass passed, $fail failed"
    exit 1
}
# tally SUITE OUT RC: a checker's output OUT's [  PASS  ] and [  FAIL  ] lines counted (a non-zero exit in the file RC
# with none failed is one failure); says "SUITE: N passed, N failed" and fails on any failure
tally() {
    pass=$(grep -c '^\[  PASS' "$2")
    fail=$(grep -c '^\[  FAIL' "$2")
    if [ "$(cat "$3" 2> /dev/null)" != 0 ] && [ "$fail" -eq 0 ]; then fail=1; fi
    echo "$1: $pass passed, $fail failed"
    [ "$fail" -eq 0 ]
}
