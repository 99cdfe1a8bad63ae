"""rss.py -- a process's own memory from /proc: VmHWM/VmRSS, and RSS split by mapping (binary, static state, heap, each library, stack).

RUSAGE_CHILDREN's ru_maxrss is the wrong figure for a child of Python: on Linux a forked child starts
with its parent's resident size, so the maximum reported is Python's. /proc/PID/status and smaps are
the child's own.
"""
import os
import re
import sys


def status(pid):
    """{'VmHWM': kB, 'VmRSS': kB, 'fds': n} of a live process, or None when it is gone."""
    try:
        with open(f"/proc/{pid}/status") as f:
            s = {k: int(v.split()[0]) for k, v in (l.split(":", 1) for l in f) if k in ("VmHWM", "VmRSS")}
        s["fds"] = len(os.listdir(f"/proc/{pid}/fd"))
        return s
    except (FileNotFoundError, ProcessLookupError, PermissionError):
        return None


def cpu_seconds(pid):
    """utime + stime of a live process, seconds."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def breakdown(pid):
    """RSS in kB by what the mapping holds."""
    out = {}
    binary = os.path.realpath(f"/proc/{pid}/exe")
    last = None  # name of the previous mapping: the anonymous one right after the binary is its .bss
    with open(f"/proc/{pid}/smaps") as f:
        name = None
        for line in f:
            m = re.match(r"^[0-9a-f]+-[0-9a-f]+ \S+ \S+ \S+ \S+\s*(.*)$", line)
            if m:
                path = m.group(1).strip()
                if path == binary:
                    name = "sonard image (text, data)"
                elif path == "" and last == "sonard image (text, data)":
                    name = "static state (.bss: pipeline, CSV reader, buffers)"
                elif path == "[heap]":
                    name = "heap (malloc: liblcm, GLib, stdio)"
                elif path == "[stack]":
                    name = "stack"
                elif path == "":
                    name = "anonymous (thread stacks, large mallocs)"
                elif path.startswith("["):
                    name = "kernel ([vdso], [vvar])"
                else:
                    base = os.path.basename(path)
                    name = "libc, libm, ld.so" if re.match(r"(libc|libm|ld-linux)", base) else \
                        "liblcm" if base.startswith("liblcm") else \
                        "GLib (LCM's dependency)" if base.startswith("libglib") else f"other: {base}"
                last = name
                continue
            if line.startswith("Rss:") and name is not None:
                out[name] = out.get(name, 0) + int(line.split()[1])
    return out


if __name__ == "__main__":
    pid = int(sys.argv[1])
    print(status(pid))
    for k, v in sorted(breakdown(pid).items(), key=lambda kv: -kv[1]):
        print(f"  {v:7d} kB  {k}")
