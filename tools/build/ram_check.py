#!/usr/bin/env python3
"""ram_check.py -- every RAM figure a header comment gives, checked against sizeof: a figure is written
`EXPR = N B` (EXPR: sizeof(struct X), whole numbers and the limits of include/sonar/config.h, joined by + and *), and
is evaluated with docs/sizes.md's sizes (a core struct's on the Cortex-M7, a host struct's on this host). Prints each
figure; exits 1 naming the file and line of any that is wrong, or whose struct docs/sizes.md does not list.
Usage: python3 tools/build/ram_check.py [docs/sizes.md]"""
import glob
import re
import sys

FIGURE = re.compile(r"((?:sizeof\(struct \w+\)|[A-Z_][A-Z0-9_]*|\d+)(?:\s*[+*]\s*(?:sizeof\(struct \w+\)|[A-Z_][A-Z0-9_]*|\d+))*)"
                    r"\s*=\s*(\d[\d ]*\d|\d) B\b")


def sizes(path):
    core, host = {}, {}
    for line in open(path):
        m = re.match(r"\| `struct (\w+)` \| (\S+) \| (\d+) \|(?: (\d+) \|)?", line)
        if m:
            (host if m.group(2).startswith("src/host/") else core)[m.group(1)] = int(m.group(3))
    return core, host


def limits():
    out = {}
    for m in re.finditer(r"#define (SONAR_\w+) (\d+)\n", open("include/sonar/config.h").read()):
        out[m.group(1)] = int(m.group(2))
    return out


def main():
    core, host = sizes(sys.argv[1] if len(sys.argv) > 1 else "docs/sizes.md")
    lim = limits()
    bad = n = 0
    for path in sorted(glob.glob("include/sonar/*.h") + glob.glob("src/host/*.h") + glob.glob("src/core/*.h")):
        for ln, text in enumerate(open(path), 1):
            for m in FIGURE.finditer(text):
                expr, want = m.group(1), int(m.group(2).replace(" ", ""))
                if "sizeof" not in expr:
                    continue   # a plain product of numbers is arithmetic, not a size
                table = host if path.startswith("src/host/") else core
                try:
                    py = re.sub(r"sizeof\(struct (\w+)\)", lambda s: str(table.get(s.group(1), core.get(s.group(1)))), expr)
                    py = re.sub(r"\b([A-Z_][A-Z0-9_]*)\b", lambda s: str(lim[s.group(1)]), py)
                    got = eval(py, {"__builtins__": {}})  # digits, + and * only by the pattern above
                except (KeyError, SyntaxError, TypeError, NameError):
                    print(f"{path}:{ln}: '{expr}': a struct or limit docs/sizes.md and config.h do not give")
                    bad += 1
                    continue
                n += 1
                if got != want:
                    print(f"{path}:{ln}: '{expr} = {m.group(2)} B' but it is {got} B")
                    bad += 1
    print(f"ram_check: {n} figures in header comments, {bad} wrong")
    return 1 if bad or n == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
