"""standalone.py -- runs one make-eval section on its own (as eval.py would call it) and prints its lines: the build and
work directories, the real recordings converted when present, the bench's figures (host, and the M7's under QEMU) when
they are built. stdlib only."""
import argparse
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def m7_figures(build):
    """The M7 bench image's figures (make mcu-bench's first image, under QEMU with -icount), when it is built and
    qemu-system-arm is installed; else {}."""
    elf = os.path.join(build, "mcu", "bench-400x1200.elf")
    if not os.path.exists(elf) or subprocess.run(["sh", "-c", "command -v qemu-system-arm"], capture_output=True).returncode:
        return {}
    r = subprocess.run(["timeout", "600", "qemu-system-arm", "-M", "mps2-an500", "-display", "none", "-monitor", "none",
                        "-icount", "shift=0", "-semihosting-config", "enable=on,target=native", "-kernel", elf,
                        "-serial", "stdio", "-serial", "null"], capture_output=True, text=True)
    return dict(p for p in (line.split(" ", 1) for line in r.stdout.splitlines()) if len(p) == 2)


def main(doc, section):
    """doc: the caller's module docstring (its first line describes it); section(sh, run, build, work, have_real,
    cost) -> the section's lines."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--real", default=os.path.join(HERE, "..", "..", "..", "shared", "data", "real"))
    ap.add_argument("--work", default="build/eval")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)

    def sh(cmd):
        return subprocess.run(cmd, check=True, capture_output=True, text=True).stdout

    def run(cmd):
        r = subprocess.run(cmd, capture_output=True, text=True)
        return r.stdout, r.stderr, r.returncode

    have_real = os.path.isdir(os.path.join(a.real, "aquascan"))
    if have_real:
        sh([sys.executable, os.path.join(HERE, "..", "data", "aquascan2csv.py"), os.path.join(a.real, "aquascan"),
            "--out", f"{a.work}/aq", "--range", "15"])
    cost = {}
    if os.path.exists(os.path.join(a.build, "bench")):
        cost = dict(p for p in (line.split() for line in sh([os.path.join(a.build, "bench")]).splitlines()) if len(p) == 2)
    cost.update({"m7_" + k: v for k, v in m7_figures(a.build).items()})
    print("\n".join(section(sh, run, a.build, a.work, have_real, cost)))
