#!/usr/bin/env python3
"""Code-shape figures for issue 22: function lengths (universal-ctags end
lines, lambdas counted inside their enclosing function) and the share of
comment lines in headers and sources. Usage: scripts/code_stats.py [--list N]
prints the figures for src/, apps/ and bench/, and the functions over N lines
(default 120)."""
import os, re, subprocess, sys

ROOTS = ["src", "apps", "bench"]

def files(exts):
    for r in ROOTS:
        for d, _, fs in os.walk(r):
            for f in sorted(fs):
                if f.endswith(exts):
                    yield os.path.join(d, f)

def functions(path):
    out = subprocess.run(["ctags", "--fields=+ne", "--c++-kinds=f", "--language-force=C++", "-o", "-", path],
                         capture_output=True, text=True).stdout
    for line in out.splitlines():
        name = line.split("\t", 1)[0]
        if name.startswith("__anon"):
            continue  # lambdas: part of the function around them
        m1, m2 = re.search(r"\bline:(\d+)", line), re.search(r"\bend:(\d+)", line)
        if m1 and m2:
            yield name, int(m1.group(1)), int(m2.group(1)) - int(m1.group(1)) + 1

def comment_share(paths):
    total = comment = 0
    for p in paths:
        in_block = False
        for raw in open(p, encoding="utf-8", errors="replace"):
            s = raw.strip()
            if not s:
                continue
            total += 1
            if in_block:
                comment += 1
                in_block = "*/" not in s
            elif s.startswith("//"):
                comment += 1
            elif s.startswith("/*"):
                comment += 1
                in_block = "*/" not in s
    return comment, total

def main():
    limit = 120
    if "--list" in sys.argv:
        limit = int(sys.argv[sys.argv.index("--list") + 1])
    long = []
    for p in files((".cpp", ".h")):
        for name, start, n in functions(p):
            if n > limit:
                long.append((n, f"{p}:{start}", name))
    long.sort(reverse=True)
    over150 = sum(1 for n, _, _ in long if n > 150)
    print(f"functions over {limit} lines: {len(long)} (over 150: {over150})")
    for n, where, name in long:
        print(f"  {n:5d}  {name}  {where}")
    for label, ext in (("headers", ".h"), ("sources", ".cpp")):
        c, t = comment_share(list(files((ext,))))
        print(f"{label}: {c} comment lines of {t} non-blank ({100.0 * c / max(t, 1):.0f}%)")

if __name__ == "__main__":
    main()
