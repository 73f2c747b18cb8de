#!/usr/bin/env python3
"""Flash/RAM per module and stack per public call for `make size`.

Usage: size_report.py VARIANT_DIR...   (each holds probe.map, probe.elf and obj/**/*.ci)
A variant dir is named <core>-<crc backend>. Flash = .text + .rodata + .data (its initial
values), RAM = .data + .bss, taken per input object from the linker map of the probe linked
with --gc-sections, i.e. only what a typical application really pulls in. Stack: from GCC's
-fcallgraph-info=su, the deepest path below each public function; an indirect call (port
operation, CRC hook) counts as the deepest operation of the STM32 port; the application's own
callbacks (completion, events) come on top.
"""
import os
import re
import sys
from collections import defaultdict

MODULES = ["frame", "crc32", "parser", "bus", "sched", "units", "strerror", "j288_stm32"]


def parse_map(path):
    """{module: [flash, ram]} from the 'Linker script and memory map' part of a GNU ld map."""
    sizes = defaultdict(lambda: [0, 0])
    text = open(path).read()
    text = text[text.find("Linker script and memory map"):]
    pending = None
    for line in text.splitlines():
        m = re.match(r"^ (\.\S+|COMMON)\s*$", line)
        if m:
            pending = m.group(1)
            continue
        m = re.match(r"^ (\.\S+|COMMON)?\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S+\.o\)?|\S+\.a\(\S+\))\s*$", line)
        if not m:
            pending = None if not line.startswith("  ") else pending
            continue
        sect = m.group(1) or pending
        pending = None
        size = int(m.group(3), 16)
        src = m.group(4)
        if sect is None or size == 0:
            continue
        base = os.path.basename(src)
        mod = base[:-2] if base.endswith(".o") else ("libc/libgcc" if ".a(" in base else base)
        if mod not in MODULES and mod not in ("size_probe", "stm32_hal_stub"):
            mod = "libc/libgcc"
        if sect.startswith((".text", ".rodata")):
            sizes[mod][0] += size
        elif sect.startswith(".data"):
            sizes[mod][0] += size
            sizes[mod][1] += size
        elif sect.startswith((".bss", "COMMON")):
            sizes[mod][1] += size
    return sizes


def parse_ci(root):
    nodes, edges = {}, defaultdict(set)
    for dirpath, _, files in os.walk(root):
        for f in files:
            if not f.endswith(".ci"):
                continue
            for line in open(os.path.join(dirpath, f)):
                m = re.match(r'node: \{ title: "([^"]+)" label: "[^"]*\\n(\d+) bytes \(([^)]*)\)', line)
                if m:
                    nodes[m.group(1)] = (int(m.group(2)), m.group(3))
                    continue
                m = re.match(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"', line)
                if m:
                    edges[m.group(1)].add(m.group(2))
    return nodes, edges


def stack_depths(nodes, edges):
    memo = {}
    ops = [n for n in nodes if re.search(r"j288_stm32\.c:op_", n)]
    notes = set()

    def depth(n, stack):
        if n in memo:
            return memo[n]
        if n in stack:
            notes.add("recursion through the port's callbacks cut at " + n.split(":")[-1])
            return 0
        own, kind = nodes.get(n, (0, "static"))
        if kind != "static":
            notes.add(n.split(":")[-1] + " has " + kind + " stack")
        stack.add(n)
        deepest = 0
        for t in edges.get(n, ()):
            if t == "__indirect_call":
                d = max([depth(o, stack) for o in ops] or [0])
            else:
                d = depth(t, stack)
            deepest = max(deepest, d)
        stack.discard(n)
        memo[n] = own + deepest
        return memo[n]

    result = {}
    for n in sorted(nodes):
        if ":" in n or not n.startswith("j288_"):
            continue  # static helpers carry a file: prefix
        result[n] = depth(n, set())
    return result, notes


def main(dirs):
    maps = {os.path.basename(d.rstrip("/")): parse_map(os.path.join(d, "probe.map")) for d in dirs}
    names = list(maps)
    print("Flash / RAM in bytes per module (-Os, --gc-sections, the size probe's use of the API):")
    print()
    print("| module | " + " | ".join(names) + " |")
    print("|---|" + "---:|" * len(names))
    mods = MODULES + ["libc/libgcc"]
    totals = {n: [0, 0] for n in names}
    for mod in mods:
        cells = []
        for n in names:
            f, r = maps[n].get(mod, [0, 0])
            totals[n][0] += f
            totals[n][1] += r
            cells.append("%d / %d" % (f, r))
        label = {"j288_stm32": "port/stm32_hal", "libc/libgcc": "libc + libgcc (memcpy, soft float)"}.get(mod, mod)
        print("| %s | %s |" % (label, " | ".join(cells)))
    print("| **total** | " + " | ".join("**%d / %d**" % tuple(totals[n]) for n in names) + " |")
    print()
    print("Caller-allocated objects (RAM, from the probe's symbols):")
    print()
    for d in dirs:
        syms = {}
        for line in os.popen("arm-none-eabi-nm -S --size-sort '%s'" % os.path.join(d, "probe.elf")):
            parts = line.split()
            if len(parts) == 4 and parts[3] in ("probe_port", "probe_sched", "probe_dma"):
                syms[parts[3]] = int(parts[1], 16)
        print("- %s: j288_stm32_t (includes j288_bus_t) %d, j288_sched_t %d, DMA buffers %d" % (
            os.path.basename(d.rstrip("/")), syms.get("probe_port", 0), syms.get("probe_sched", 0),
            syms.get("probe_dma", 0)))
    print()
    stacks = {}
    all_notes = set()
    for d in dirs:
        nodes, edges = parse_ci(os.path.join(d, "obj"))
        stacks[os.path.basename(d.rstrip("/"))], notes = stack_depths(nodes, edges)
        all_notes |= notes
    print("Stack per public call in bytes (deepest path; indirect calls = the deepest port operation;")
    print("the application's completion and event callbacks come on top):")
    print()
    print("| function | " + " | ".join(names) + " |")
    print("|---|" + "---:|" * len(names))
    funcs = sorted(set().union(*[set(s) for s in stacks.values()]))
    for fn in funcs:
        print("| %s | %s |" % (fn, " | ".join(str(stacks[n].get(fn, "-")) for n in names)))
    if all_notes:
        print()
        for n in sorted(all_notes):
            print("note: " + n)


if __name__ == "__main__":
    main(sys.argv[1:])
