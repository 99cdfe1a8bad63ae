# lib.sh -- shared by the shell test scripts: pass/fail counting and a check that shows its output on failure.
# The caller sets T (a scratch directory) before calling check.
pass=0
fail=0
ok() { pass=$((pass + 1)); echo "[  PASS  ] $1"; }
ko() { fail=$((fail + 1)); echo "[  FAIL  ] $1"; }
# check "what" command...: runs the command, PASS on exit 0, else FAIL with its output indented
check() { what=$1; shift; if "$@" > "$T/out" 2>&1; then ok "$what"; else ko "$what"; sed 's/^/    /' "$T/out"; fi; }
# NETNS: the command that runs a command in a network namespace of its own: unshare -n as root (a user namespace
# cannot be made inside a chroot, as make fresh-check's is), unshare -rn otherwise.
if [ "$(id -u)" -eq 0 ] && unshare -n true 2> /dev/null; then NETNS="unshare -n"; else NETNS="unshare -rn"; fi
# need_netns SUITE WHAT: ends the suite, failed, when $NETNS (a network namespace of its own, for WHAT) is not allowed;
# the suites that run in a chroot (ros2.sh, in make fresh-check) use $NETNS, the others unshare -rn
need_netns() {
    $NETNS true 2> /dev/null && return 0
    ko "$1: $NETNS ($2) is not allowed here"
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
