# apt.sh -- sourced by the scripts that fetch Debian packages (deps.sh, arm_sysroot.sh, fresh_check.sh, the BlueOS
# build): a package index that cannot be fetched is a warning naming it, a failed fetch is tried once more, and only
# a package that cannot be had is an error, named. A mirror in mid-sync (an index whose size does not match its
# Release file) or a suite that is down must not stop a build whose packages come from elsewhere.
# Needs: $APT_WHO (the caller's name for its messages) and $sudo ("" as root, "sudo" otherwise).

# apt_update: apt-get update, tried twice; what still fails is said, index by index, and the lists apt has are used.
apt_update() {
    _log=$(mktemp /tmp/sonard-apt.XXXXXX)
    if $sudo apt-get update -qq > "$_log" 2>&1; then rm -f "$_log"; return 0; fi
    echo "$APT_WHO: warning: apt-get update failed; trying once more in 5 s" >&2
    sleep 5
    if $sudo apt-get update -qq > "$_log" 2>&1; then rm -f "$_log"; return 0; fi
    # apt names each index it could not fetch on an "E:" or "W:" line ("Failed to fetch URL  why").
    grep -E '^(E|W|Err):' "$_log" | sed "s/^/$APT_WHO: warning: package index not updated: /" >&2
    echo "$APT_WHO: warning: going on with the package lists apt already has; a package is an error only if it cannot be had" >&2
    rm -f "$_log"
    return 0
}

# apt_unavailable PKG...: prints those of PKG that no source apt knows offers (no install candidate).
apt_unavailable() {
    for _p in "$@"; do
        _c=$(apt-cache policy "${_p}" 2> /dev/null | sed -n 's/^ *Candidate: *//p')
        { [ -z "$_c" ] || [ "$_c" = "(none)" ]; } && printf ' %s' "${_p}"
    done
    return 0
}

# apt_install PKG...: installs them without their Recommends, tried twice (an update between); a failure names the
# packages that cannot be had, or says that all could be but the download or install failed, with apt's words.
apt_install() {
    _log=$(mktemp /tmp/sonard-apt.XXXXXX)
    # shellcheck disable=SC2086
    if $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$@" > "$_log" 2>&1; then
        rm -f "$_log"; return 0
    fi
    echo "$APT_WHO: warning: apt-get install failed; updating the lists and trying once more" >&2
    apt_update
    if $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$@" > "$_log" 2>&1; then
        rm -f "$_log"; return 0
    fi
    _gone=$(apt_unavailable "$@")
    if [ -n "$_gone" ]; then
        echo "$APT_WHO: error: no package source offers:$_gone (apt-cache policy: no candidate)" >&2
    else
        echo "$APT_WHO: error: installing $* failed though every one is offered; apt said:" >&2
    fi
    grep -E '^(E|W):' "$_log" | tail -5 | sed "s/^/$APT_WHO:   /" >&2
    rm -f "$_log"
    return 1
}

# retry_once WHAT CMD...: runs CMD; when it fails, says so and runs it once more (a mirror's hiccup).
retry_once() {
    _what=$1; shift
    "$@" && return 0
    echo "$APT_WHO: warning: $_what failed; trying once more in 5 s" >&2
    sleep 5
    "$@"
}
