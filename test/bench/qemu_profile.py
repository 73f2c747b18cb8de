#!/usr/bin/env python3
"""usage: qemu_profile.py LOG [ELF NM [FUNCTION]]

Instructions per function from a QEMU log taken with `-d in_asm,exec,nochain -D LOG`: each
translated block's instruction count (in_asm) times its executions (exec), summed by the
function that holds the block's first instruction (from `NM -n ELF`, else QEMU's own
symbol). A profiling aid for the benchmarks under QEMU; prints the top functions, or with
FUNCTION, that function's blocks (address, instructions executed)."""
import bisect
import re
import subprocess
import sys
from collections import Counter

def main():
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    syms = []
    if len(sys.argv) >= 4:
        out = subprocess.run([sys.argv[3], "-n", sys.argv[2]], capture_output=True,
                             text=True, check=True).stdout
        for line in out.splitlines():
            f = line.split()
            if len(f) == 3 and f[1] in "tTwW":
                syms.append((int(f[0], 16) & ~1, f[2]))
    addrs = [a for a, _ in syms]
    size = {}
    execs = Counter()
    cur = None
    ins_re = re.compile(r"^0x([0-9a-f]+):")
    exec_re = re.compile(r"^Trace \d+: \S+ \[[0-9a-f]+/([0-9a-f]+)/")
    with open(sys.argv[1], errors="replace") as log:
        for line in log:
            if line.startswith("IN:"):
                cur = None
                continue
            m = ins_re.match(line)
            if m:
                pc = int(m.group(1), 16)
                if cur is None:
                    cur = pc
                    size[cur] = 0
                size[cur] += 1
                continue
            if not line.strip():
                cur = None
                continue
            m = exec_re.match(line)
            if m:
                execs[int(m.group(1), 16)] += 1
    per_fn = Counter()
    blocks = []
    for pc, n in execs.items():
        i = bisect.bisect_right(addrs, pc) - 1
        name = syms[i][1] if i >= 0 else hex(pc)
        per_fn[name] += n * size.get(pc, 0)
        if len(sys.argv) >= 5 and name == sys.argv[4]:
            blocks.append((pc, n, size.get(pc, 0)))
    if blocks:
        for pc, n, sz in sorted(blocks):
            print(f"0x{pc:08x}  {n:8d} x {sz:3d} = {n * sz:9d}")
        return 0
    total = sum(per_fn.values())
    print(f"{total} instructions")
    for name, n in per_fn.most_common(40):
        print(f"{n:10d}  {name}")
    return 0

if __name__ == "__main__":
    sys.exit(main())
